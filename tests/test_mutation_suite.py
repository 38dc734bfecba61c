"""The mutation suite: every reader × every mutation kind on small slices of real files.

Each reader reads a small head slice of a real file from ``../shared/data`` (read in place; the slice is
cut into a scratch folder, never into the repository) or, for formats the folder does not hold (OEM,
TDM, OMM, navigation CSV, typed telemetry), the same real data written in that format by abrupt's writer
or by sgp4's OMM exporter. The mutation kinds and the verdict are in ``tests/mutation_harness.py``:
every mutated run must be abrupt's one-line error naming the file, a counted repair, or the unmutated
rows (a subset of them where a whole record was removed), within 60 s and with the process's peak
memory rising by less than 1 GB. Deterministic: no random draws but seeded ones.

The default suite runs each reader in-process on its slice; ``-m slow`` repeats the memory-hostile
kinds (a 50 MB line, 5 MB of garbage) in a child process whose own peak memory is measured.
"""

from __future__ import annotations

import atexit
import functools
import gzip
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd
import pytest

import mutation_harness as mh
from abrupt.errors import RepairLog
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import ingest_archives
from abrupt.pipelines.tracking import read_tracking_arrays
from abrupt.readers.aer import read_aer
from abrupt.readers.cpf import read_cpf
from abrupt.readers.crd import read_crd
from abrupt.readers.fengyun import read_fengyun_maneuvers
from abrupt.readers.ids_maneuvers import read_ids_maneuvers
from abrupt.readers.navigation_csv import read_navigation_csv, write_navigation_csv
from abrupt.readers.oem import read_oem, write_oem
from abrupt.readers.omm import read_omm
from abrupt.readers.orekit_od_input import read_od_input
from abrupt.readers.sinex import read_sinex
from abrupt.readers.sp3 import parse_sp3, read_sp3
from abrupt.readers.tdm import write_tdm
from abrupt.readers.telemetry import read_telemetry
from abrupt.readers.tle import read_tle, tle_checksum
from abrupt.store import TelemetryStore

PROJECT = Path(__file__).resolve().parent.parent
SHARED = PROJECT.parent / "shared" / "data"
KESTREL_TOML = PROJECT / "examples" / "spacecraft" / "kestrel.toml"
ARCHIVE = "flight-like/telemetry/KESTREL2_2026-03-10.csv.gz"


# ------------------------------------------------------------------------------------------------
# Rows: what each reader returned, comparable across runs


def _value(x: Any) -> Any:
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, pd.Timestamp | np.datetime64):
        return str(x)
    if isinstance(x, float):
        return x
    return x if isinstance(x, int | str | bool | type(None)) else str(x)


def _frame_rows(frame: pd.DataFrame) -> mh.Rows:
    """The rows without their source line numbers (which a deleted line above shifts)."""
    frame = frame.drop(columns=[c for c in ("line", "line_no") if c in frame.columns])
    return [tuple(_value(v) for v in row) for row in frame.itertuples(index=False)]


def _counts(log: RepairLog) -> Counter[str]:
    return Counter(log.counts)


def _ephemeris_outcome(eph: Any) -> mh.Outcome:
    rows = [
        (str(t), *map(float, p), *map(float, v))
        for t, p, v in zip(eph.times_utc, eph.position_m, eph.velocity_mps, strict=True)
    ]
    return mh.Outcome(rows, _counts(eph.repairs))


def _table_reader(reader: Callable[..., pd.DataFrame]) -> Callable[[Path], mh.Outcome]:
    def run(path: Path) -> mh.Outcome:
        log = RepairLog(str(path))
        return mh.Outcome(_frame_rows(reader(path, repairs=log)), _counts(log))

    return run


def _elements_outcome(history: Any) -> mh.Outcome:
    return mh.Outcome(_frame_rows(history.elements), _counts(history.repairs))


def _tracking_outcome(path: Path) -> mh.Outcome:
    """The path ``abrupt detect tracking --setup od_test_W3.in`` runs: the measurements on the set-up's
    stations (which the implied-orbit check needs: a range in the wrong unit is refused there)."""
    setup = read_od_input(_companion("tracking/od_test_W3.in"))
    log = RepairLog(str(path))
    data = read_tracking_arrays(path, setup, refraction=setup.refraction_correction, repairs=log)
    rows = [
        (str(t), name, *map(float, y)) for t, name, y in zip(data.times_utc, data.station_names, data.y, strict=True)
    ]
    return mh.Outcome(rows, _counts(log))


def _od_outcome(path: Path) -> mh.Outcome:
    setup = read_od_input(path)
    rows: mh.Rows = [(str(setup.epoch_utc), *map(float, setup.initial_state))]
    rows += [(name, repr(st), setup.range_bias_estimated.get(name)) for name, st in sorted(setup.stations.items())]
    rows += [
        (k, repr(getattr(setup, k)))
        for k in ("earth_rotation", "theta0_rad", "mu_m3_s2", "elevation_mask_deg", "refraction_correction")
    ]
    rows += sorted(setup.extra.items())
    return mh.Outcome(rows)


def _sinex_outcome(path: Path) -> mh.Outcome:
    rows: mh.Rows = []
    for code, station in sorted(read_sinex(path).items()):
        for s in station.solutions:
            rows.append((code, repr(s)))
        for e in station.eccentricities:
            rows.append((code, repr(e)))
    return mh.Outcome(rows)


def _spacecraft_outcome(path: Path) -> mh.Outcome:
    """The path a user runs with the file: load it, then ``abrupt ingest --spacecraft`` of a real archive
    slice (its [flight] channels bound the telemetry). Rows: the file's fields and the stored samples;
    counts: ingest's and one per documented default the file took."""
    sc = load_spacecraft(path)
    rows = [(k, repr(v)) for k, v in sorted(vars(sc).items()) if k not in ("source", "defaults")]
    scratch = Path(tempfile.mkdtemp(prefix="abrupt-mutation-spacecraft-"))
    try:
        archive = scratch / "KESTREL2_2026-03-10.csv"
        archive.write_bytes(_archive_slice())
        summary = ingest_archives([archive], _companion("flight-like/decoder.csv"), scratch / "store", spacecraft=sc)
        counts: Counter[str] = Counter(sc.defaults)
        for day in summary.days:
            counts.update(day.get("removed", {}))
        start, end = np.datetime64("2026-03-09", "ns"), np.datetime64("2026-03-12", "ns")
        samples = TelemetryStore(scratch / "store").read_range("SC-A", start, end)
        return mh.Outcome(rows + _frame_rows(samples), counts)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def _archive_outcome(path: Path) -> mh.Outcome:
    """``abrupt ingest --spacecraft kestrel.toml`` into a fresh store: the stored samples and every count."""
    store = Path(tempfile.mkdtemp(prefix="abrupt-mutation-store-"))
    try:
        return _ingested(path, store)
    finally:
        shutil.rmtree(store, ignore_errors=True)


KESTREL = load_spacecraft(KESTREL_TOML)


def _ingested(path: Path, store: Path) -> mh.Outcome:
    summary = ingest_archives([path], _companion("flight-like/decoder.csv"), store, spacecraft=KESTREL)
    counts: Counter[str] = Counter()
    for file_counts in summary.files.values():
        counts.update(file_counts)
    for day in summary.days:
        counts.update(day.get("removed", {}))
        counts.update(day.get("reported", {}))
    start, end = np.datetime64("2026-03-09", "ns"), np.datetime64("2026-03-12", "ns")
    samples = TelemetryStore(store).read_range("SC-A", start, end) if summary.rows_added else pd.DataFrame()
    return mh.Outcome(_frame_rows(samples), counts)


def _telemetry_outcome(spacecraft: Any) -> Callable[[Path], mh.Outcome]:
    def run(path: Path) -> mh.Outcome:
        tm = read_telemetry(path, spacecraft)
        rows = [
            (str(t), *map(float, q), *map(float, w), *map(float, o))
            for t, q, w, o in zip(tm.time, tm.quaternion_BN, tm.body_rate_rad_s, tm.wheel_speed_rad_s, strict=True)
        ]
        return mh.Outcome(rows, _counts(tm.repairs))

    return run


# ------------------------------------------------------------------------------------------------
# Slices of the real files


def _real(rel: str) -> Path:
    path = SHARED / rel
    if not path.exists():
        pytest.skip(f"real dataset {rel} not found under {SHARED}")
    return path


_COMPANIONS = Path(tempfile.mkdtemp(prefix="abrupt-mutation-companions-"))
_COMPANIONS.chmod(0o755)
atexit.register(shutil.rmtree, _COMPANIONS, True)


@functools.cache
def _companion(rel: str) -> Path:
    """A world-readable copy of a real companion file (a tracking set-up, a decoder) in the system's
    temporary folder. The "unreadable" mutation runs the reader as an unprivileged user, which must be
    refused the file under test only: the checkout and ``../shared`` may sit in a private folder."""
    copy = _COMPANIONS / rel.replace("/", "__")
    shutil.copyfile(_real(rel), copy)
    copy.chmod(0o644)
    return copy


def _text(rel: str) -> str:
    return _real(rel).read_bytes().decode("latin-1")


def _sp3_slice(n_epochs: int = 60) -> bytes:
    lines = _text("sp3/ssaja102.b03007.e03017.DGS.sp3").splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("*")]
    out = [*lines[: starts[n_epochs]], "EOF"]
    out[0] = out[0][:32] + f"{n_epochs:7d}" + out[0][39:]
    return ("\n".join(out) + "\n").encode()


def _sp3_ephemeris(scratch: Path) -> Any:
    path = scratch / "source.sp3"
    path.write_bytes(_sp3_slice())
    return parse_sp3(path).ephemerides["L08"]


def _oem_slice(scratch: Path, form: Literal["kvn", "xml"] = "kvn") -> bytes:
    path = scratch / "source.oem"
    write_oem(_sp3_ephemeris(scratch), path, form=form)
    return path.read_bytes()


def _nav_slice(scratch: Path) -> bytes:
    path = scratch / "source.csv"
    write_navigation_csv(_sp3_ephemeris(scratch), path)
    return path.read_bytes()


def _cpf_slice() -> bytes:
    lines = _text("tracking/ilrs-corpus/lageos1_cpf_180613_16401.hts").splitlines()
    head = [line for line in lines if line[:1] in "Hh"]
    records = [line for line in lines if line.startswith(("10 ", "20 "))][:80]
    return ("\n".join([*head, *records, "99"]) + "\n").encode()


def _lines_slice(rel: str, n: int) -> bytes:
    return ("\n".join(_text(rel).splitlines()[:n]) + "\n").encode()


def _tle_lines() -> list[str]:
    return _text("tle/Jason-3.tle").splitlines()[:160]


def _omm_slice() -> bytes:
    from sgp4.api import Satrec
    from sgp4.exporter import export_omm

    lines = _tle_lines()
    out = []
    for a, b in zip(lines[0::2], lines[1::2], strict=True):
        out.append("CCSDS_OMM_VERS = 2.0")
        out += [f"{k} = {v}" for k, v in export_omm(Satrec.twoline2rv(a, b), "JASON 3").items()]
    return ("\n".join(out) + "\n").encode()


def _tdm_slice(scratch: Path) -> bytes:
    src = scratch / "source.aer"
    src.write_bytes(_lines_slice("tracking/W3B.aer", 140))
    path = scratch / "source.tdm"
    write_tdm(read_aer(src), path, spacecraft="W3B")
    return path.read_bytes()


def _tle_fixup(line: bytes) -> bytes:
    """A TLE line with its checksum recomputed (the mutation reaches the physical checks)."""
    text = line.decode("latin-1")
    if len(text) >= 69 and text[0] in "12":
        text = text[:68] + str(tle_checksum(text))
    return text.encode("latin-1")


def _telemetry_files(scratch: Path) -> tuple[bytes, Path]:
    """Real flight-like telemetry as a typed table (1 Hz star tracker, gyro deg/s, wheels rpm) and the
    spacecraft file that maps it: kestrel.toml plus a [telemetry] table."""
    if not (SHARED / ARCHIVE).exists():
        pytest.skip(f"real dataset {ARCHIVE} not found under {SHARED}")
    with gzip.open(SHARED / ARCHIVE, "rt") as f:
        head = [next(f) for _ in range(8000)]
    long = pd.read_csv(io.StringIO("".join(head)))
    long["time"] = pd.to_datetime(long["time"])
    long["name"] = long["mnemonic"].str.rsplit(".", n=1).str[-1]
    wide = long.pivot_table(index="time", columns="name", values="value", aggfunc="first").sort_index()
    wide = wide.ffill().dropna(subset=["ST_Q0"])
    wide = wide[wide.index.isin(long.loc[long["name"] == "ST_Q0", "time"])].dropna()
    cols = {"ST_Q0": "q0", "ST_Q1": "q1", "ST_Q2": "q2", "ST_Q3": "q3", "GYRO_X": "wx", "GYRO_Y": "wy"}
    cols |= {"GYRO_Z": "wz", "RW1_SPD": "rw1", "RW2_SPD": "rw2", "RW3_SPD": "rw3", "RW4_SPD": "rw4"}
    table = wide[list(cols)].rename(columns=cols).reset_index()
    table["time"] = table["time"].dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ")
    toml = KESTREL_TOML.read_text().split("\n[flight]")[0] + (
        '\n[telemetry]\ntime = { column = "time" }\n'
        'quaternion = { columns = ["q0", "q1", "q2", "q3"], order = "scalar_first", frame = "q_BN" }\n'
        'body_rate = { columns = ["wx", "wy", "wz"], unit = "deg/s" }\n'
        'wheel_speed = { columns = ["rw1", "rw2", "rw3", "rw4"], unit = "rpm" }\n'
    )
    sc = scratch / "kestrel_telemetry.toml"
    sc.write_text(toml)
    return table.to_csv(index=False).encode(), sc


def _to_parquet(data: bytes) -> bytes:
    """The mutated CSV as Parquet (text cells kept as text); bytes that are no table stay as they are."""
    try:
        frame = pd.read_csv(io.BytesIO(data), dtype=str, encoding="latin-1", keep_default_na=False)
        buf = io.BytesIO()
        for c in frame.columns[1:]:
            numbers = pd.to_numeric(frame[c], errors="coerce")
            if numbers.notna().sum() == (frame[c] != "").sum():
                frame[c] = numbers
        frame.to_parquet(buf, index=False)
        return buf.getvalue()
    except Exception:
        return data


def _starts(*prefixes: bytes) -> Callable[[bytes], bool]:
    return lambda line: line.startswith(prefixes)


def _specs() -> dict[str, mh.ReaderSpec]:
    tel_sc: dict[str, Any] = {}

    def tel_build(shared: Path, scratch: Path) -> bytes:
        data, sc = _telemetry_files(scratch)
        tel_sc["path"] = load_spacecraft(sc)
        return data

    def tel_run(path: Path) -> mh.Outcome:
        return _telemetry_outcome(tel_sc["path"])(path)

    is_tel_row = _starts(b"2026-")
    specs = [
        mh.ReaderSpec("sp3", "m.sp3", lambda d, s: _sp3_slice(), lambda p: _ephemeris_outcome(read_sp3(p, "L08")),
                      _starts(b"P"), (0, 1, 2)),
        mh.ReaderSpec("oem", "m.oem", lambda d, s: _oem_slice(s), lambda p: _ephemeris_outcome(read_oem(p)),
                      _starts(b"20"), (-6, -5, -4)),
        mh.ReaderSpec("oem_xml", "m.xml", lambda d, s: _oem_slice(s, "xml"),
                      lambda p: _ephemeris_outcome(read_oem(p)), _starts(b"          <X "), (0,),
                      unit_record=_starts(b"          <X ", b"          <Y ", b"          <Z ")),
        mh.ReaderSpec("cpf", "m.cpf", lambda d, s: _cpf_slice(), lambda p: _ephemeris_outcome(read_cpf(p)),
                      _starts(b"10 "), (-3, -2, -1)),
        mh.ReaderSpec("navigation_csv", "m.csv", lambda d, s: _nav_slice(s),
                      lambda p: _ephemeris_outcome(read_navigation_csv(p)), _starts(b"20"), (-6, -5, -4)),
        mh.ReaderSpec("crd", "m.npt", lambda d, s: _text_bytes("tracking/ilrs-corpus/lageos2_201802.npt.v2C"),
                      _table_reader(read_crd), _starts(b"11 "), (2,), unit_record=_starts(b"20 "),
                      unit_fields=(2,)),
        mh.ReaderSpec("tle", "m.tle", lambda d, s: ("\n".join(_tle_lines()) + "\n").encode(),
                      lambda p: _elements_outcome(read_tle(p)), _starts(b"2 "), (-2,), fixup=_tle_fixup),
        mh.ReaderSpec("omm", "m.omm", lambda d, s: _omm_slice(), lambda p: _elements_outcome(read_omm(p)),
                      _starts(b"MEAN_MOTION ="), (0,)),
        mh.ReaderSpec("tdm", "m.tdm", lambda d, s: _tdm_slice(s), _tracking_outcome, _starts(b"RANGE ="), (-1,)),
        mh.ReaderSpec("aer", "m.aer", lambda d, s: _lines_slice("tracking/W3B.aer", 140), _tracking_outcome,
                      _starts(b"2010-"), (-1,)),
        mh.ReaderSpec("orekit_setup", "m.in", lambda d, s: _text_bytes("tracking/od_test_W3.in"), _od_outcome,
                      lambda line: b"=" in line and not line.lstrip().startswith(b"#"), (-1,)),
        mh.ReaderSpec("sinex", "m.snx", lambda d, s: _text_bytes("tracking/SLRF2014_POS+VEL_2030.0_200428.snx"),
                      _sinex_outcome, lambda line: line[7:10] in (b"STA", b"VEL"), (-2,)),
        mh.ReaderSpec("ids_maneuvers", "m.txt", lambda d, s: _lines_slice("maneuvers/ja3man.txt", 30),
                      _table_reader(read_ids_maneuvers), _starts(b"JASO3"), (16,)),
        mh.ReaderSpec("fengyun_maneuvers", "m.fy", lambda d, s: _text_bytes("maneuvers/manFY2D.txt.fy"),
                      _table_reader(read_fengyun_maneuvers), _starts(b"GEO"), (3,)),
        mh.ReaderSpec("telemetry_csv", "m.csv", tel_build, tel_run, is_tel_row, (4, 5, 6)),
        mh.ReaderSpec("telemetry_parquet", "m.parquet", tel_build, tel_run, is_tel_row, (4, 5, 6),
                      binary=_to_parquet),
        mh.ReaderSpec("archive_ingest", "KESTREL2_2026-03-10.csv",
                      lambda d, s: _archive_slice(), _archive_outcome, _starts(b"2026-"), (-1,),
                      named_as="SC-A_2026-03-10.csv"),
        mh.ReaderSpec("spacecraft_toml", "m.toml", lambda d, s: KESTREL_TOML.read_bytes(), _spacecraft_outcome,
                      lambda line: b"=" in line and not line.lstrip().startswith(b"#") and b"max_speed" in line,
                      (0,)),
    ]  # fmt: skip
    return {s.name: s for s in specs}


def _text_bytes(rel: str) -> bytes:
    _text(rel)
    return (SHARED / rel).read_bytes()


def _archive_slice() -> bytes:
    if not (SHARED / ARCHIVE).exists():
        pytest.skip(f"real dataset {ARCHIVE} not found under {SHARED}")
    with gzip.open(SHARED / ARCHIVE, "rb") as f:
        return b"".join(next(f) for _ in range(3000))


SPECS = _specs()


@pytest.fixture(scope="module")
def clean_runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[bytes, mh.Outcome]]:
    return {}


def _clean(name: str, cache: dict[str, tuple[bytes, mh.Outcome]], scratch: Path) -> tuple[bytes, mh.Outcome]:
    if name not in cache:
        spec = SPECS[name]
        text = spec.build(SHARED, scratch)
        path = scratch / f"clean-{spec.filename}"
        path.write_bytes(spec.binary(text) if spec.binary else text)
        cache[name] = (text, mh.run_clean(spec, path))
    return cache[name]


@pytest.mark.parametrize("name", list(SPECS))
def test_every_mutation_is_refused_repaired_or_harmless(
    name: str, tmp_path: Path, clean_runs: dict[str, tuple[bytes, mh.Outcome]]
) -> None:
    spec = SPECS[name]
    text, clean = _clean(name, clean_runs, tmp_path)
    assert len(clean.rows) >= 4, f"{name}: the unmutated slice gave {len(clean.rows)} rows"
    verdicts = [mh.judge(spec, kind, text, clean, tmp_path) for kind in mh.ALL_KINDS]
    bad = [
        v
        for v in verdicts
        if v.verdict == "traceback" or (v.verdict == "silent wrong" and v.kind not in spec.beyond_reach)
    ]
    heavy = [v for v in verdicts if v.rss_rise_bytes > mh.MEMORY_BOUND_BYTES]
    table = "\n".join(f"  {v.kind:22s} {v.verdict:12s} {v.detail}" for v in verdicts)
    assert not bad and not heavy, f"{name}:\n{table}"
    assert len(verdicts) >= 15


def test_the_harness_sees_a_silent_change(tmp_path: Path, clean_runs: dict[str, tuple[bytes, mh.Outcome]]) -> None:
    """The verdict is not vacuous: a value moved in a navigation CSV's time column, with nothing
    counted, is reported as silently wrong (the harness's own check)."""
    _, clean = _clean("navigation_csv", clean_runs, tmp_path)
    shifted = mh.Outcome([(r[0], r[1] + 1.0, *r[2:]) for r in clean.rows], clean.repairs)
    assert mh._compare("nan", shifted, clean) == "silent wrong"
    assert mh._compare("delete_line", mh.Outcome(clean.rows[:-1], clean.repairs), clean) == "subset"
    assert mh._compare("nan", mh.Outcome(clean.rows[:-1], clean.repairs), clean) == "silent wrong"


def _child_peak(script: str) -> tuple[int, str]:
    proc = subprocess.Popen(
        [sys.executable, "-c", script],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        env={**os.environ, "PYTHONPATH": str(PROJECT / "src") + os.pathsep + str(PROJECT / "tests")},
    )
    out, _ = proc.communicate(timeout=600)
    return proc.returncode, out.decode(errors="replace")


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SPECS))
def test_hostile_sizes_in_a_child_process(name: str, tmp_path: Path) -> None:
    """A 50 MB line and 5 MB of garbage: the child process's own peak memory stays under 1 GB."""
    script = (
        "import json, resource, sys\n"
        "import mutation_harness as mh\n"
        "mh.LONG_LINE_CHARS = 50_000_000\n"
        "mh.MUTATIONS['garbage'] = lambda d, s: __import__('random').Random(1).randbytes(5_000_000)\n"
        "import test_mutation_suite as t\n"
        "from pathlib import Path\n"
        f"scratch = Path({str(tmp_path)!r})\n"
        f"text, clean = t._clean({name!r}, {{}}, scratch)\n"
        f"v = [mh.judge(t.SPECS[{name!r}], k, text, clean, scratch) for k in ('long_line', 'garbage')]\n"
        "print(json.dumps([[x.kind, x.verdict, x.detail] for x in v]))\n"
        "print('PEAK', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)\n"
    )
    code, out = _child_peak(script)
    assert code == 0, out[-2000:]
    peak = int(out.rsplit("PEAK", 1)[1].split()[0])
    verdicts = json.loads(out.rsplit("PEAK", 1)[0].strip().splitlines()[-1])
    assert all(v[1] not in ("traceback", "silent wrong") for v in verdicts), verdicts
    print(f"{name}: child peak resident memory {peak / 2**20:.0f} MiB; {verdicts}")
    assert peak < mh.MEMORY_BOUND_BYTES, f"{name}: peak {peak / 2**20:.0f} MiB"


def _counter_names(path: Path) -> list[str]:
    """Counter names a reader module uses: ``.record(NAME, n)``, the archive's ``counts[NAME]``,
    ``.removed[NAME]``/``.reported[NAME]``, ``.count(..., NAME, reported=...)`` and its label loop, and
    module constants named ``SP3_*``/``TLE_*``/``ARCHIVE_*``. An f-string gives its literal parts."""
    import ast

    tree = ast.parse(path.read_text())
    consts = {
        t.id: n.value.value
        for n in tree.body
        if isinstance(n, ast.Assign) and isinstance(n.value, ast.Constant) and isinstance(n.value.value, str)
        for t in n.targets
        if isinstance(t, ast.Name)
    }
    found: list[ast.expr] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            if node.func.attr == "record" and node.args:
                found.append(node.args[0])
            elif node.func.attr == "count" and len(node.args) >= 4:
                found.append(node.args[3])
        elif isinstance(node, ast.Subscript) and isinstance(node.ctx, ast.Load | ast.Store):
            target = node.value
            name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
            if name in ("counts", "removed", "reported"):
                found.append(node.slice)
        elif isinstance(node, ast.For) and isinstance(node.iter, ast.Tuple):
            found += [e.elts[0] for e in node.iter.elts if isinstance(e, ast.Tuple) and e.elts]
    names = [v for k, v in consts.items() if k.startswith(("SP3_", "TLE_", "ARCHIVE_"))]
    for expr in found:
        if isinstance(expr, ast.Constant) and isinstance(expr.value, str):
            names.append(expr.value)
        elif isinstance(expr, ast.Name) and expr.id in consts:
            names.append(consts[expr.id])
        elif isinstance(expr, ast.JoinedStr):
            names += [v.value for v in expr.values if isinstance(v, ast.Constant) and v.value.strip(" ()")]
    return names


def test_every_repair_counter_is_in_the_formats_page() -> None:
    doc = (PROJECT / "docs" / "formats.md").read_text().replace("\\|", "|")
    modules = [*sorted((PROJECT / "src" / "abrupt" / "readers").glob("*.py"))]
    modules.append(PROJECT / "src" / "abrupt" / "massprops" / "telemetry.py")
    names = {(p.name, n) for p in modules for n in _counter_names(p)}
    assert len(names) >= 60  # the extraction finds the counters (there are more than 60)
    missing = sorted(f"{module}: {name!r}" for module, name in names if name.strip() not in doc)
    assert not missing, "counters missing from docs/formats.md:\n" + "\n".join(missing)
