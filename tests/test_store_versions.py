"""The store keeps one version of a day: a corrected archive replaces the stored day (said and counted),
a repeated ingest (after a kill, or by mistake) changes neither rows nor counters, archives of separate
parts of a day add up, and a broken ``ingest.json`` is a one-line error naming the file.

Archives are written in the test's folder; the truth is the archive text itself (which samples and
values a day must hold after each ingest)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.cli.main import main
from abrupt.errors import InputError, OutputError
from abrupt.pipelines.flight import ingest_archives
from abrupt.store import TelemetryStore, merge_version

DAY = "2026-03-10"


def _decoder(tmp: Path) -> Path:
    p = tmp / "decoder.csv"
    p.write_text("real_name,pseudonym\nBIRD,SC-B\nBIRD.A,SC-B.ch01\nBIRD.B,SC-B.ch02\n")
    return p


def _archive(tmp: Path, name: str, rows: list[tuple[int, str, float]]) -> Path:
    """An archive of ``(second of the day, mnemonic, value)`` rows (with one placeholder row, removed
    and counted by ingest, so that the day's counters have something to count)."""
    lines = [f"{DAY}T{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}.000Z,{m},{v!r}" for s, m, v in rows]
    lines.append(f"{DAY}T23:59:59.000Z,BIRD.A,-999999")
    p = tmp / name
    p.write_text("time,mnemonic,value\n" + "\n".join(lines) + "\n")
    return p


def _day(store: Path) -> dict[tuple[str, int], float]:
    frame = TelemetryStore(store).read_day("SC-B", DAY)
    seconds = (pd.DatetimeIndex(frame["time"]).asi8 // 1_000_000_000) % 86_400
    return {(str(m), int(s)): float(v) for m, s, v in zip(frame["mnemonic"], seconds, frame["value"], strict=True)}


def _rows(n: int, offset: float = 0.0, start_s: int = 0) -> list[tuple[int, str, float]]:
    return [(start_s + k, "BIRD.A" if k % 2 else "BIRD.B", float(k) + offset) for k in range(n)]


def test_a_repeated_ingest_changes_no_row_and_no_counter(tmp_path: Path) -> None:
    archive = _archive(tmp_path, "BIRD_day.csv", _rows(200))
    store = tmp_path / "store"
    ingest_archives([archive], _decoder(tmp_path), store)
    first = TelemetryStore(store).report("SC-B", DAY)
    for _ in range(3):  # a killed run re-run, then twice more by mistake
        summary = ingest_archives([archive], _decoder(tmp_path), store)
        assert summary.rows_added == 0
    again = TelemetryStore(store).report("SC-B", DAY)
    for key in ("rows_kept", "rows_stored", "removed", "samples_per_channel", "versions_replaced"):
        assert again[key] == first[key], key
    assert first["rows_stored"] == 200 and first["removed"] == {"placeholder values": 1}
    assert "unchanged" in again["last_ingest"]


def test_a_run_killed_between_samples_and_report_is_repaired_by_ingesting_again(tmp_path: Path) -> None:
    """The samples file was replaced, the report not (the kill came between the two renames): ingesting
    the archive again gives the counters of one ingest."""
    archive = _archive(tmp_path, "BIRD_day.csv", _rows(200))
    store = tmp_path / "store"
    ingest_archives([archive], _decoder(tmp_path), store)
    report_path = store / "spacecraft=SC-B" / f"day={DAY}" / "ingest.json"
    once = json.loads(report_path.read_text())
    stale = {k: v for k, v in once.items() if k != "archives"}  # as a report without per-archive counts
    report_path.write_text(json.dumps(stale))
    ingest_archives([archive], _decoder(tmp_path), store)
    repaired = json.loads(report_path.read_text())
    assert repaired["rows_kept"] == once["rows_kept"] and repaired["rows_stored"] == 200
    assert repaired["removed"] == once["removed"]


def test_a_corrected_archive_replaces_the_day_and_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    store = tmp_path / "store"
    dec = _decoder(tmp_path)
    main(["ingest", str(_archive(tmp_path, "BIRD_day.csv", _rows(300))), "--decoder", str(dec), "--store", str(store)])
    corrected = _rows(250, offset=0.5)  # every value changed, and the last 50 samples withdrawn
    capsys.readouterr()
    arch = _archive(tmp_path, "BIRD_day_v2.csv", corrected)
    main(["ingest", str(arch), "--decoder", str(dec), "--store", str(store)])
    out = capsys.readouterr().out
    day = _day(store)
    assert len(day) == 250  # the withdrawn samples are gone
    expected = {("SC-B.ch01" if m == "BIRD.A" else "SC-B.ch02", s): v for s, m, v in corrected}
    assert day == expected  # one value per sample: the corrected one
    report = TelemetryStore(store).report("SC-B", DAY)
    assert report["versions_replaced"] == 1 and report["rows_stored"] == 250
    assert report["sources"] == ["BIRD_day_v2.csv".replace("BIRD", "SC-B")]
    assert "replaced the stored version" in out and "250 sample(s) with another value" in out


def test_the_same_archive_name_with_other_content_replaces_its_samples(tmp_path: Path) -> None:
    """A corrected archive under the same name that only withdraws samples (no value conflicts)."""
    store, dec = tmp_path / "store", _decoder(tmp_path)
    ingest_archives([_archive(tmp_path, "BIRD_day.csv", _rows(100))], dec, store)
    ingest_archives([_archive(tmp_path, "BIRD_day.csv", _rows(100)[::2])], dec, store)
    assert len(_day(store)) == 50
    report = TelemetryStore(store).report("SC-B", DAY)
    assert report["versions_replaced"] == 1 and report["rows_kept"] == 50


def test_archives_of_separate_parts_of_a_day_add_up(tmp_path: Path) -> None:
    store, dec = tmp_path / "store", _decoder(tmp_path)
    morning = _archive(tmp_path, "BIRD_am.csv", _rows(100))
    evening = _archive(tmp_path, "BIRD_pm.csv", _rows(100, start_s=43_200))
    ingest_archives([morning], dec, store)
    ingest_archives([evening], dec, store)
    ingest_archives([morning, evening], dec, store)  # both again: nothing changes
    report = TelemetryStore(store).report("SC-B", DAY)
    assert len(_day(store)) == 200 and report["rows_stored"] == 200 and report["rows_kept"] == 200
    assert report["versions_replaced"] == 0 and report["removed"] == {"placeholder values": 2}


def test_merge_version_counts_against_the_sample_sets() -> None:
    """Independent truth: the sets of (mnemonic, time, value) before and after."""
    rng = np.random.default_rng(5)
    old = pd.DataFrame({"mnemonic": ["a", "b"] * 50, "time": np.arange(100) * 10, "value": rng.normal(size=100)})
    new = old.iloc[20:60].copy()
    new.loc[new.index[::4], "value"] += 1.0  # 10 conflicting values
    merged = merge_version(old, new)
    assert merged.conflicts == 10 and merged.replaced == 10 and merged.added == 10
    truth = set(map(tuple, old.iloc[:20].to_numpy().tolist())) | set(map(tuple, old.iloc[60:].to_numpy().tolist()))
    truth |= set(map(tuple, new.to_numpy().tolist()))
    assert set(map(tuple, merged.frame.to_numpy().tolist())) == truth and len(merged.frame) == 100
    same = merge_version(old, old.iloc[10:30])
    assert (same.added, same.replaced, len(same.frame)) == (0, 0, 100)


def test_a_broken_ingest_report_is_one_line_naming_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    store, dec = tmp_path / "store", _decoder(tmp_path)
    archive = _archive(tmp_path, "BIRD_day.csv", _rows(20))
    ingest_archives([archive], dec, store)
    report_path = store / "spacecraft=SC-B" / f"day={DAY}" / "ingest.json"
    report_path.write_text(report_path.read_text()[:40])  # a write cut short
    with pytest.raises(InputError, match=r"ingest\.json: ingest report is not valid JSON"):
        TelemetryStore(store).report("SC-B", DAY)
    with pytest.raises(SystemExit) as info:
        main(["ingest", str(archive), "--decoder", str(dec), "--store", str(store)])
    err = capsys.readouterr().err.strip().splitlines()
    assert info.value.code == 2 and len(err) == 1 and str(report_path) in err[0]


def test_the_ingest_report_is_written_atomically(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A write that fails half-way leaves the previous report whole (and no temporary file)."""
    store, dec = tmp_path / "store", _decoder(tmp_path)
    ingest_archives([_archive(tmp_path, "BIRD_am.csv", _rows(20))], dec, store)
    folder = store / "spacecraft=SC-B" / f"day={DAY}"
    before = (folder / "ingest.json").read_text()

    def cut(self: Path, text: str, *args: object, **kwargs: object) -> int:
        with open(self, "w") as fh:
            fh.write(text[:30])
        raise OSError(28, "No space left on device")

    evening = _archive(tmp_path, "BIRD_pm.csv", _rows(20, start_s=43_200))
    monkeypatch.setattr(Path, "write_text", cut)
    with pytest.raises(OutputError, match=r"ingest\.json: cannot write it: no space left on device"):
        ingest_archives([evening], dec, store)
    monkeypatch.undo()
    assert (folder / "ingest.json").read_text() == before
    assert sorted(p.name for p in folder.iterdir()) == ["ingest.json", "samples.parquet"]
