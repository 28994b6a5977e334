"""The case store: atomic versioned files, conflicts, listeners, ids that stay inside the store, reloads."""

from __future__ import annotations

import json
import threading
from pathlib import Path, PurePosixPath

import pytest

from app.store import CaseExists, CaseNotFound, CaseStore, InvalidId, VersionConflict, check_id, slugify, stock_id
from lanevil_core.case import Case
from lanevil_core.illusions.shadow import FenceShadow


@pytest.fixture
def store(tmp_path: Path) -> CaseStore:
    return CaseStore(tmp_path / "data")


def shadow_case(severity: int = 2) -> Case:
    return Case(title="Fence shadow", illusions=[FenceShadow(severity=severity)])


def test_create_writes_an_envelope_and_no_temp_files(store: CaseStore) -> None:
    record = store.create(shadow_case(), case_id="fence")
    store.update("fence", Case(title="renamed"), expected_version=1)
    assert sorted(path.name for path in store.folder.iterdir()) == ["fence.json"]
    data = json.loads((store.folder / "fence.json").read_text(encoding="utf-8"))
    assert (data["id"], data["version"], data["case"]["title"]) == ("fence", 2, "renamed")
    assert data["created_at"] == record.created_at <= data["updated_at"]


def test_versions_bump_and_stale_writes_conflict(store: CaseStore) -> None:
    store.create(shadow_case(), case_id="fence")
    assert store.update("fence", shadow_case(3)).version == 2
    assert store.update("fence", shadow_case(4), expected_version=2).version == 3
    with pytest.raises(VersionConflict) as conflict:
        store.update("fence", shadow_case(5), expected_version=2)
    assert (conflict.value.expected, conflict.value.current) == (2, 3)
    assert "version 3" in str(conflict.value) and conflict.value.field == "version"
    assert store.get("fence").severity == 4
    with pytest.raises(VersionConflict):
        store.delete("fence", expected_version=1)
    assert "fence" in store


def test_create_existing_and_missing_ids(store: CaseStore) -> None:
    store.create(shadow_case(), case_id="fence")
    with pytest.raises(CaseExists):
        store.create(shadow_case(), case_id="fence")
    with pytest.raises(CaseNotFound):
        store.get("nothing")
    with pytest.raises(CaseNotFound):
        store.update("nothing", shadow_case())
    with pytest.raises(CaseNotFound):
        store.delete("nothing")


def test_new_ids_come_from_titles_and_never_collide(store: CaseStore) -> None:
    first = store.create(Case(title="Night Rain!"))
    second = store.create(Case(title="Night Rain!"))
    assert (first.id, second.id) == ("night-rain", "night-rain-2")


@pytest.mark.parametrize("case_id", ["../evil", "..", "a/b", "a\\b", ".hidden", "UPPER", "", "a" * 81, "x\x00",
                                     "-lead"])
def test_invalid_ids_touch_no_file(store: CaseStore, tmp_path: Path, case_id: str) -> None:
    for call in (lambda: store.create(shadow_case(), case_id=case_id), lambda: store.get(case_id),
                 lambda: store.update(case_id, shadow_case()), lambda: store.delete(case_id)):
        with pytest.raises(InvalidId):
            call()
    assert not any(tmp_path.rglob("*.json"))


def test_listeners_hear_every_change_until_unsubscribed(store: CaseStore) -> None:
    heard: list[tuple[str, str, int | None]] = []
    unsubscribe = store.subscribe(lambda kind, case_id, record: heard.append(
        (kind, case_id, record.version if record else None)))
    store.create(shadow_case(), case_id="fence")
    store.update("fence", shadow_case(3))
    store.delete("fence")
    unsubscribe()
    store.create(shadow_case(), case_id="quiet")
    assert heard == [("created", "fence", 1), ("updated", "fence", 2), ("deleted", "fence", None)]


def test_the_writer_hears_of_its_update_before_the_listeners(store: CaseStore) -> None:
    order: list[str] = []
    store.subscribe(lambda kind, case_id, record: order.append(f"listener {kind}"))
    store.create(shadow_case(), case_id="fence")
    record = store.update("fence", shadow_case(3), on_stored=lambda stored: order.append(f"writer {stored.version}"))
    assert record.version == 2 and order == ["listener created", "writer 2", "listener updated"]


def test_reload_from_disk_keeps_versions_and_cases(store: CaseStore) -> None:
    store.create(shadow_case(), case_id="fence")
    store.update("fence", shadow_case(5))
    store.create(Case(title="clean"), case_id="clean")
    reopened = CaseStore(store.root)
    assert len(reopened) == 2
    assert reopened.get("fence").version == 2 and reopened.get("fence").severity == 5
    assert reopened.get("fence").case == store.get("fence").case
    assert reopened.update("fence", shadow_case(1), expected_version=2).version == 3


def test_concurrent_updates_of_one_version_one_wins(store: CaseStore) -> None:
    store.create(shadow_case(), case_id="fence")
    writers = 8
    barrier = threading.Barrier(writers)
    outcomes: list[str] = []

    def write(severity: int) -> None:
        barrier.wait()
        try:
            store.update("fence", shadow_case(severity % 5 + 1), expected_version=1)
            outcomes.append("ok")
        except VersionConflict:
            outcomes.append("conflict")

    threads = [threading.Thread(target=write, args=(n,)) for n in range(writers)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sorted(outcomes) == ["conflict"] * (writers - 1) + ["ok"]
    assert store.get("fence").version == 2


def test_summary_files_stock_originals_under_their_folder_type(tmp_path: Path) -> None:
    scenes = Path(__file__).resolve().parents[2] / "scenes"
    original = scenes / "30_shadow/fence_shadow/00_uphill_rural_noon/00_original.json"
    store = CaseStore(tmp_path / "data")
    record = store.create(Case.model_validate_json(original.read_text()), case_id="orig",
                          origin="30_shadow/fence_shadow/00_uphill_rural_noon/00_original.json")
    summary = record.summary()
    assert (summary["type"], summary["category"], summary["severity"]) == ("fence_shadow", "shadow", 0)


def test_id_helpers() -> None:
    assert check_id("fence_shadow-03_level3") == "fence_shadow-03_level3"
    assert slugify("  Héllo, World ") == "h-llo-world"
    assert stock_id(PurePosixPath("00_clean/00_straight_urban.json")) == "clean-00_straight_urban"
    relative = PurePosixPath("30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json")
    assert stock_id(relative) == "fence_shadow-00_uphill_rural_noon-03_level3"  # one folder per original
    assert stock_id(PurePosixPath("30_shadow/fence_shadow/03_level3.json")) == "fence_shadow-03_level3"  # per type


def test_a_new_store_removes_what_a_killed_write_left(tmp_path: Path) -> None:
    folder = tmp_path / "data" / "cases"
    folder.mkdir(parents=True)
    stale = folder / ".fence.json.999999999.x1y2z3.tmp"
    stale.write_text("{half a case")
    store = CaseStore(tmp_path / "data")
    assert not stale.exists() and len(store) == 0
