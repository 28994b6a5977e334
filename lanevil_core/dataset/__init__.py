"""Dataset generation at scale: the benchmark's test split and a clean train split, rendered on local processes
or a Dask cluster, resumable, with a manifest that pins every frame's inputs and hash.

Modules: ``plan`` (which frames go where), ``worker`` (render + encode one chunk), ``writer`` (the output
folder), ``manifest`` (versions, frame keys, manifest.json), ``local`` (process pool), ``distributed`` (Dask),
``progress`` (tqdm bar), ``run`` (``generate_dataset``).
"""

from .plan import DatasetPlan, PlanError, Settings, build_plan, discover_cases, evenly_spaced
from .run import RunSummary, generate_dataset

__all__ = [
    "DatasetPlan",
    "PlanError",
    "RunSummary",
    "Settings",
    "build_plan",
    "discover_cases",
    "evenly_spaced",
    "generate_dataset",
]
