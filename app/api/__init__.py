"""The REST API under ``/api`` (``docs/api.md``): its resources in ``routes/`` (one router module each, mounted in
``routes/__init__.py``), and here what every route shares: the error body and route class (``errors``), body
limits (``limits``), ``Allow`` headers (``allow``), dependencies (``deps``), query parameters (``params``), strict
JSON and form bodies (``json_body``, ``forms``), request and job bodies (``case_bodies``, ``job_bodies``) and the
OpenAPI document (``openapi``)."""
