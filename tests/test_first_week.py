"""What a new user trips over in the first week: a store opened with another spacecraft's file, help that
misses a description or a sub-command's spelling, kinds the catalog refuses, figures that hide their
thresholds."""

from __future__ import annotations

from pathlib import Path

import pytest

from abrupt.catalog import Catalog
from abrupt.cli.main import main
from abrupt.detect.base import detector_names, get_detector
from abrupt.errors import InputError
from abrupt.events import Event, events_frame
from abrupt.kinds import EVENT_KIND_MEANINGS, EVENT_KINDS
from abrupt.pipelines.flight import day_range
from abrupt.simulate.confounders import CONFOUNDER_CLASS
from abrupt.store import TelemetryStore

ROOT = Path(__file__).resolve().parent.parent
THESIS_TOML = ROOT / "examples" / "spacecraft" / "thesis.toml"


def _store_with_days(root: Path, spacecraft: str, days: list[str]) -> TelemetryStore:
    """A store layout holding ``days`` of ``spacecraft`` (the day listing reads the partition files only)."""
    for day in days:
        folder = root / f"spacecraft={spacecraft}" / f"day={day}"
        folder.mkdir(parents=True)
        (folder / "samples.parquet").write_bytes(b"")
    return TelemetryStore(root)


def test_a_store_opened_with_another_spacecraft_file_names_what_it_holds(tmp_path: Path) -> None:
    store = _store_with_days(tmp_path / "store", "SC-A", ["2026-03-10", "2026-03-11", "2026-03-12"])
    with pytest.raises(InputError, match=r"'thesis'.*holds 'SC-A' \(3 day\(s\), 2026-03-10\.\.2026-03-12\)"):
        day_range(store, "thesis", None)


def test_an_empty_store_says_it_is_empty(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="holds no spacecraft days"):
        day_range(TelemetryStore(tmp_path), "thesis", None)


def test_detect_attitude_on_a_store_of_another_spacecraft_is_one_line_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    store = _store_with_days(tmp_path / "store", "SC-A", ["2026-03-10"])
    args = ["detect", "attitude", "--store", str(store.root), "--spacecraft", str(THESIS_TOML)]
    with pytest.raises(SystemExit) as exc:
        main([*args, "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "'thesis'" in err and "'SC-A' (1 day(s), 2026-03-10..2026-03-10)" in err


def test_every_kind_a_detector_or_attribution_writes_is_in_the_documented_vocabulary() -> None:
    written = {get_detector(name).kind for name in detector_names()} | set(CONFOUNDER_CLASS.values())
    assert written <= set(EVENT_KINDS)
    assert all(EVENT_KIND_MEANINGS[kind].strip() for kind in EVENT_KINDS)


def _event_of_kind(kind: str, day: int) -> Event:
    return Event(
        spacecraft="sat-a",
        kind=kind,
        detector="attitude.glr",
        time_utc=f"2026-01-{day:02d}T00:00:00",
        statistic=7.0,
        threshold=5.0,
        false_alarms_per_day=1.0,
        run_id="r",
        config_hash="cfg",
    )


@pytest.mark.parametrize("kind", EVENT_KINDS)
def test_catalog_list_filters_on_every_kind_and_shows_it_whole(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = str(tmp_path / "c.sqlite")
    Catalog(target).add_events(events_frame([_event_of_kind(k, i + 1) for i, k in enumerate(EVENT_KINDS)]))
    main(["catalog", "list", "--catalog", target, "--kind", kind])
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2  # the header and the one event of this kind
    assert lines[1].split()[2] == kind  # time, spacecraft, then the kind, whole
    assert max(len(line) for line in lines) <= 120
