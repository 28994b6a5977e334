"""The API through a real uvicorn server and HTTP client: what TestClient cannot show (sockets, real concurrency,
limits enforced on the wire)."""

from __future__ import annotations

import io
from concurrent.futures import ThreadPoolExecutor

import httpx
from PIL import Image

SHADOW_ID = "fence_shadow-00_uphill_rural_noon-03_level3"


def test_crud_render_and_conflicts_over_http(live_server) -> None:
    with httpx.Client(base_url=live_server.url, timeout=60) as client:
        assert client.get("/api/cases").json()["count"] == 6
        envelope = client.get(f"/api/cases/{SHADOW_ID}")
        assert envelope.headers["etag"] == '"1"'
        created = client.post("/api/cases", json={"id": "over-http", "case": envelope.json()["case"]})
        assert created.status_code == 201 and created.headers["location"].startswith(live_server.url)

        def write(number: int) -> int:
            with httpx.Client(base_url=live_server.url, timeout=60) as own:
                return own.patch("/api/cases/over-http", json={"title": f"writer {number}"},
                                 headers={"If-Match": '"1"'}).status_code

        with ThreadPoolExecutor(6) as pool:
            statuses = sorted(pool.map(write, range(6)))
        assert statuses == [200] + [409] * 5
        assert live_server.state.store.get("over-http").version == 2

        frame = client.get("/api/cases/over-http/frames/3.jpg", params={"width": 160, "height": 90, "overlay": True})
        assert frame.status_code == 200 and Image.open(io.BytesIO(frame.content)).size == (160, 90)
        cached = client.get("/api/cases/over-http/frames/3.jpg", params={"width": 160, "height": 90, "overlay": True},
                            headers={"If-None-Match": frame.headers["etag"]})
        assert cached.status_code == 304
        assert client.delete("/api/cases/over-http", headers={"If-Match": '"2"'}).status_code == 204


def test_limits_and_bad_ids_over_http(live_server) -> None:
    limit = live_server.state.settings.max_body_bytes
    with httpx.Client(base_url=live_server.url, timeout=60) as client:
        response = client.post("/api/cases", content=b" " * (limit + 1), headers={"content-type": "application/json"})
        assert response.status_code == 413 and response.json()["field"] == "body"
        for raw in ("/api/cases/..%2F..%2Fsettings", "/api/cases/%2e%2e", "/api/cases/a%00b"):
            assert client.get(raw).status_code in (404, 422)
        assert client.get("/api/illusions").json()["count"] == 14
