"""The LanEvil Studio web application (FastAPI back end and viser editor); it only translates HTTP and
browser events into ``lanevil_core`` calls."""
