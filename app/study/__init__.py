"""The human perception study: pages under ``/study`` (``pages``), its API under ``/api/study``
(``app/api/routes/study.py``).

An organiser creates a study from generated frames and uploaded real photos (``POST /api/study/studies``); participants
rate each image once on the 5-point ACR scale; results are MOS with 95 % CIs per source, illusion type and
severity after screening raters on gold and trapping items (``stats``). See ``docs/study.md``.
"""
