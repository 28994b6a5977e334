"""Server settings: from ``LANEVIL_*`` environment variables, overridden by ``lanevil serve`` flags."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import Field, field_validator
from pydantic_settings import BaseSettings, NoDecode, SettingsConfigDict

# Server limits: the defaults of the settings below and of the frame service (app/frames.py) that takes them.
FRAME_CACHE_BYTES = 256_000_000  # rendered frames and their encodings kept (LRU)
SCENE_CACHE_BYTES = 128_000_000  # compiled scenes kept for reuse (a stock scene: 7 to 170 MB once rendered)
MAX_RENDERS = 2  # frames rendered at once (each on every core); a render's buffers are the server's peak memory
MAX_RENDER_QUEUE = 32  # requests waiting for a render slot before the next is told to come back later

class Settings(BaseSettings):
    """Everything the backend, the editor and the study read at start-up."""

    model_config = SettingsConfigDict(env_prefix="LANEVIL_", extra="ignore")

    host: str = Field("127.0.0.1", description="address both servers bind (loopback unless set)")
    port: int = Field(8000, ge=0, le=65535, description="HTTP port of the API, website and study (0 = any free)")
    editor_port: int = Field(8080, ge=0, le=65535, description="port of the viser editor (0 = any free)")
    data_dir: Path = Field(Path("data"), description="case store, exports, render cache and study database")
    scenes_dir: Path = Field(Path("scenes"), description="stock cases copied into an empty store on first start")
    admin_token: str | None = Field(None, description="bearer token of the perception-study organiser (unset: `lanevil "
                                    "serve` generates one into DATA/admin_token and reuses it)")
    max_body_bytes: int = Field(2_000_000, ge=1024, description="largest JSON request body")
    max_upload_bytes: int = Field(20_000_000, ge=1024, description="largest uploaded image")
    max_width: int = Field(1920, description="largest rendered frame width")
    max_height: int = Field(1080, description="largest rendered frame height")
    max_jobs: int = Field(16, ge=1, description="export jobs queued or running before clients get 429")
    max_jobs_per_client: int = Field(4, ge=1, description="export jobs one client may have queued or running")
    frame_cache_bytes: int = Field(FRAME_CACHE_BYTES, ge=0, description="memory budget of the rendered-frame LRU cache")
    max_renders: int = Field(MAX_RENDERS, ge=1, description="frames rendered at once; more requests wait for a slot")
    max_render_queue: int = Field(MAX_RENDER_QUEUE, ge=0,
                                  description="requests waiting for a render slot before clients get 503")
    scene_cache_bytes: int = Field(SCENE_CACHE_BYTES, ge=0, description="memory budget of the compiled-scene cache")
    malloc_arenas: int = Field(2, ge=0, description="glibc malloc arenas of the server process (0 = glibc's default); "
                               "fewer arenas keep the resident memory of concurrent renders down")
    render_threads: int = Field(0, ge=0, description="threads per rendered frame (0 = every core this process may use)")
    editor: bool = Field(True, description="start the viser editor beside the API")
    allowed_origins: Annotated[list[str], NoDecode] = Field(
        default_factory=list, description="more origins whose pages may open the editor's websocket, comma-separated "
        "(`http://studio.example:8080`; `*` = any); always allowed: the editor's and the API's ports on localhost, "
        "127.0.0.1, [::1] and the bound host")

    @field_validator("allowed_origins", mode="before")
    @classmethod
    def _comma_separated(cls, value: object) -> object:
        if isinstance(value, str):
            return [origin.strip() for origin in value.split(",") if origin.strip()]
        return value
