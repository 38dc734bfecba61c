"""A fleet row may name an ingested store (and a spacecraft file) instead of a telemetry file: the row is
the flight pipeline over that spacecraft's stored days, with the events ``abrupt detect attitude
--store`` gives, and the strike injected into the archive is found at its time. The store exports to a
long archive that ingests back to the same samples.

Truth: the strikes written into the synthetic archives (tests/flight_synth) and the direct command.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.catalog import Catalog
from abrupt.cli.main import main
from abrupt.errors import InputError
from abrupt.events import read_events
from abrupt.pipelines.fleet import read_manifest
from abrupt.store import TelemetryStore
from flight_synth import make_archive

STRIKE_S = 7200.0  # [s] after the archive's start (2026-01-05T00:00Z)


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """One store holding SC-Z, with a strike two hours into its 5 h archive; its spacecraft file."""
    work = tmp_path_factory.mktemp("fleetstore")
    archive = make_archive(work / "a", hours=5.0, strikes=[(STRIKE_S, [0.08, -0.05, 0.03])])
    main(["-q", "ingest", str(archive.archive), "--decoder", str(archive.decoder), "--store", str(work / "store")])
    return work, archive.spacecraft


def test_a_fleet_row_naming_a_store_finds_the_strike_as_the_store_command_does(store: tuple[Path, Path]) -> None:
    work, spacecraft = store
    (work / "fleet.csv").write_text(f"spacecraft,telemetry,spacecraft_file,store\nSC-Z,,{spacecraft},store\n")
    catalog = str(work / "fleet.sqlite")
    main(["-q", "detect", "fleet", str(work / "fleet.csv"), "--out", str(work / "fleet.csv.parquet"),
          "--catalog", catalog])  # fmt: skip
    fleet = read_events(str(work / "fleet.csv.parquet"))
    main(["-q", "detect", "attitude", "--store", str(work / "store"), "--spacecraft", str(spacecraft),
          "--out", str(work / "direct.csv"), "--catalog", str(work / "direct.sqlite")])  # fmt: skip
    direct = read_events(str(work / "direct.csv"))
    assert sorted(fleet["event_id"]) == sorted(direct["event_id"])  # the same pipeline, configuration, events
    times = pd.to_datetime(fleet["time_utc"].astype(str), utc=True).dt.tz_localize(None)
    offset_s = (times - pd.Timestamp("2026-01-05T00:00:00")).dt.total_seconds()
    strikes = fleet[(offset_s - STRIKE_S).abs() < 30.0]
    assert len(strikes) == 1 and strikes["dH_Nms"].iloc[0] == pytest.approx(
        np.linalg.norm([0.08, -0.05, 0.03]), rel=0.1
    )
    with Catalog(catalog, create=False).engine.connect() as conn:
        spans = pd.read_sql("SELECT spacecraft, detector, start_utc, end_utc FROM coverage", conn)
    assert spans["spacecraft"].tolist() == ["SC-Z"] and spans["detector"].tolist() == ["attitude.flight_glr"]
    assert str(spans["start_utc"].iloc[0]).startswith("2026-01-05")


def test_a_store_row_for_a_spacecraft_the_store_does_not_hold_names_what_it_holds(store: tuple[Path, Path]) -> None:
    work, spacecraft = store
    bad = work / "bad.csv"
    bad.write_text(f"spacecraft,telemetry,spacecraft_file,store\nSC-Q,,{spacecraft},store\n")
    with pytest.raises(InputError) as err:
        read_manifest(bad)
    assert str(err.value).startswith(f"{bad}:2:")
    assert "holds no days of spacecraft 'SC-Q'; it holds SC-Z (1 days)" in str(err.value)
    both = work / "both.csv"
    both.write_text(f"spacecraft,telemetry,spacecraft_file,store\nSC-Z,{spacecraft},{spacecraft},store\n")
    with pytest.raises(InputError, match="a telemetry file or a store, not both"):
        read_manifest(both)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_store_exports_to_an_archive_that_ingests_back_to_the_same_samples(
    store: tuple[Path, Path], tmp_path: Path, suffix: str
) -> None:
    work, _ = store
    out = tmp_path / f"SC-Z{suffix}"
    main(["-q", "store", "export", str(work / "store"), "--spacecraft", "SC-Z", "--out", str(out)])
    original = TelemetryStore(work / "store")
    mnemonics = sorted(set(original.read_day("SC-Z", "2026-01-05")["mnemonic"].astype(str)))
    # New pseudonyms for a second store: a decoder may not map a name to itself (a pseudonym must not
    # carry a real name), so the exported names are mapped to FLEET-B and mapped back to compare.
    renamed = {"SC-Z": "FLEET-B", **{m: "FLEET-B" + m.removeprefix("SC-Z") for m in mnemonics}}
    assert not any(real.lower() in new.lower() for real in renamed for new in renamed.values())
    decoder = tmp_path / "decoder.csv"
    decoder.write_text("real_name,pseudonym\n" + "".join(f"{real},{new}\n" for real, new in renamed.items()))
    main(["-q", "ingest", str(out), "--decoder", str(decoder), "--store", str(tmp_path / "again")])
    again = TelemetryStore(tmp_path / "again")
    back = {new: real for real, new in renamed.items()}
    assert again.days("FLEET-B") == original.days("SC-Z")
    for day in original.days("SC-Z"):
        a = original.read_day("SC-Z", day).astype({"mnemonic": str}).sort_values(["mnemonic", "time"])
        b = again.read_day("FLEET-B", day).astype({"mnemonic": str})
        b = b.assign(mnemonic=b["mnemonic"].map(back)).sort_values(["mnemonic", "time"])
        assert len(a) == len(b) > 0
        assert (a["mnemonic"].to_numpy() == b["mnemonic"].to_numpy()).all()
        assert (a["time"].to_numpy() == b["time"].to_numpy()).all()
        np.testing.assert_array_equal(a["value"].to_numpy(), b["value"].to_numpy())


def test_the_evidence_table_beside_out_never_overwrites_an_input(
    store: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    work, spacecraft = store
    manifest = work / "run.evidence.csv"  # the name the evidence of --out run.csv would take
    manifest.write_text(f"spacecraft,telemetry,spacecraft_file,store\nSC-Z,,{spacecraft},store\n")
    before = manifest.read_bytes()
    with pytest.raises(SystemExit) as exc:
        main(["detect", "fleet", str(manifest), "--out", str(work / "run.csv"), "--catalog", str(work / "g.sqlite")])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "same file as --manifest" in err and "destroy that input" in err
    assert manifest.read_bytes() == before and not (work / "run.csv").exists()
