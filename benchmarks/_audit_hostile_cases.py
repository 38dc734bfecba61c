"""Audit cases of the kinds the judge adds, for every reader and command (``bench_audit_cases.py``): files
damaged the way they are in the field (a cut last line, BOM, CRLF, Latin-1, an empty file, a folder where a
file is expected), values in another unit or frame, epochs in the future, wrapped or out of order,
duplicated or interleaved records, NaN, inf and huge numbers, implausible physics (orbits inside the Earth,
beyond the Moon, hyperbolic), and outputs aimed at inputs.

Each case damages a clean input written by abrupt's own writers or simulators (the truth orbit of
``_audit_cases.truth_orbit``, the quiet TLE history, the simulated ``.aer`` of a spacecraft that does not
manoeuvre), so any event of a damaged run is caused by the damage. A benign change of encoding (CRLF,
BOM) is a control: exit 0 and no event.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from _audit_cases import (
    KESTREL_TOML,
    ROOT,
    THESIS_TOML,
    Case,
    Run,
    cases_of,
    itrf,
    shift_epoch_years,
    truth_orbit,
    with_field,
)
from _audit_door_cases import DAY, _archive, _decoder, _history
from abrupt.model.frames import gcrf_to_itrf
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.readers.oem import write_oem
from abrupt.readers.sp3 import write_sp3
from abrupt.series.ephemeris import Ephemeris

sys.path.insert(0, str(ROOT / "tests"))


QUIET = ["--false-alarms-per-year", "1"]


def _no_event(out: str, err: str, folder: Path) -> str | None:
    path = folder / "e.csv"
    events = pd.read_csv(path, comment="#") if path.exists() and path.stat().st_size else pd.DataFrame()
    return f"{len(events)} event(s) from a clean input re-encoded" if len(events) else None


# ------------------------------------------------------------------------------------------------ bytes


def crlf(data: bytes) -> bytes:
    return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n")


def bom(data: bytes) -> bytes:
    return b"\xef\xbb\xbf" + data


def cut_last_line(data: bytes) -> bytes:
    """The file cut in the middle of its last non-empty line (a write interrupted)."""
    body = data.rstrip(b"\n")
    start = body.rfind(b"\n") + 1
    return body[: start + max(1, (len(body) - start) // 2)]


def empty(data: bytes) -> bytes:
    return b""


def header_only(data: bytes) -> bytes:
    return data.split(b"\n", 1)[0] + b"\n"


def latin1_line(marker: bytes, line: bytes) -> Callable[[bytes], bytes]:
    """``line`` (holding a byte of Latin-1) written after the first line that starts with ``marker``."""

    def edit(data: bytes) -> bytes:
        lines = data.split(b"\n")
        k = next(i for i, old in enumerate(lines) if old.startswith(marker))
        return b"\n".join([*lines[: k + 1], line, *lines[k + 1 :]])

    return edit


def _rewrite(path: Path, edit: Callable[[bytes], bytes]) -> None:
    path.write_bytes(edit(path.read_bytes()))


# ------------------------------------------------------------------------------------------------ TLE


def _tle(edit: Callable[[bytes], bytes] | None = None, said: str | None = None, ok: bool = False) -> Callable:
    def build(folder: Path) -> Run:
        h = _history(folder)
        if edit is not None:
            _rewrite(h, edit)
        run = Run(["detect", "tle", h.name, "--out", "e.csv", "--catalog", "c.sqlite", *QUIET], [h.name], said=said)
        if ok:
            run.ok, run.check = True, _no_event
        return run

    return build


def _tle_folder(folder: Path) -> Run:
    (folder / "h.tle").mkdir()
    return Run(["detect", "tle", "h.tle", "--out", "e.csv", "--catalog", "c.sqlite"], [], names="h.tle")


def _tle_lines(edit: Callable[[list[str]], list[str]]) -> Callable[[bytes], bytes]:
    return lambda data: ("\n".join(edit(data.decode().splitlines())) + "\n").encode()


def _interleaved(lines: list[str]) -> list[str]:
    """The element sets of two halves interleaved (epochs not monotone)."""
    sets = [lines[i : i + 2] for i in range(0, len(lines), 2)]
    half = len(sets) // 2
    mixed = [s for pair in zip(sets[half:], sets[:half], strict=False) for s in pair]
    return [line for s in mixed for line in s]


def _set_field(start: int, text: str, line: int = 1) -> Callable[[list[str]], list[str]]:
    """Every set (``line`` 0 or 1 of each) with ``text`` written at column ``start``."""

    def edit(lines: list[str]) -> list[str]:
        return [with_field(ln, start, text) if i % 2 == line else ln for i, ln in enumerate(lines)]

    return edit


def _one_set_field(start: int, text: str, line: int = 1) -> Callable[[list[str]], list[str]]:
    def edit(lines: list[str]) -> list[str]:
        k = (len(lines) // 4) * 2 + line
        return [with_field(ln, start, text) if i == k else ln for i, ln in enumerate(lines)]

    return edit


def _year_wrap(lines: list[str]) -> list[str]:
    """One set's epoch year moved 50 years on: its two digits wrap to the previous century."""
    k = (len(lines) // 4) * 2
    return [shift_epoch_years(ln, 50) if i == k else ln for i, ln in enumerate(lines)]


def _every_year(years: int) -> Callable[[list[str]], list[str]]:
    return lambda lines: [shift_epoch_years(ln, years) if i % 2 == 0 else ln for i, ln in enumerate(lines)]


TLE = cases_of(
    "hostile files: TLE",
    [
        ("tle CRLF line ends (control)", _tle(crlf, ok=True)),
        ("tle UTF-8 BOM (control)", _tle(bom, ok=True)),
        ("tle last line cut in half", _tle(cut_last_line, "skipped|truncat|incomplete")),
        ("tle empty file", _tle(empty)),
        ("tle a folder named h.tle", _tle_folder),
        ("tle two halves interleaved", _tle(_tle_lines(_interleaved), "sorted|order")),
        ("tle one epoch year wraps to 1976", _tle(_tle_lines(_year_wrap), "isolated|gap|departs|dropped")),
        ("tle every mean motion 0.02 rev/day (beyond the Moon)", _tle(_tle_lines(_set_field(52, " 0.02000000")))),
        ("tle every mean motion 0", _tle(_tle_lines(_set_field(52, " 0.00000000")))),
        ("tle one inclination 200 deg", _tle(_tle_lines(_one_set_field(8, "200.0000")), "skipped|dropped")),
        ("tle one B* 9.9e+9", _tle(_tle_lines(_one_set_field(53, " 99999+9", 0)), "skipped|dropped|departs")),
        ("tle every eccentricity 0.9 (perigee inside)", _tle(_tle_lines(_set_field(26, "9000000")))),
        ("tle every epoch 40 years ahead", _tle(_tle_lines(_every_year(40)))),
    ],
)


# ------------------------------------------------------------------------------------------------ ephemerides


def _orbit(
    fmt: str,
    damage: Callable[[Ephemeris], Ephemeris] | None = None,
    edit: Callable[[bytes], bytes] | None = None,
    said: str | None = None,
    ok: bool = False,
    hours: float = 6.0,
    **kw: object,
) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        truth = truth_orbit(hours=hours, **kw)  # type: ignore[arg-type]
        eph = itrf(truth) if fmt == "sp3" else truth
        eph = damage(eph) if damage is not None else eph
        path = folder / f"o.{fmt.replace('-xml', '')}"
        if fmt == "oem-xml":
            write_oem(eph, path, form="xml")
        else:
            {"sp3": write_sp3, "oem": write_oem, "csv": write_navigation_csv}[fmt](eph, path)
        if edit is not None:
            _rewrite(path, edit)
        run = Run(["detect", "orbit", path.name, "--out", "e.csv", "--catalog", "c.sqlite"], [path.name], said=said)
        if ok:
            run.ok, run.check = True, _no_event
        return run

    return build


def _scaled(fr: float, fv: float) -> Callable[[Ephemeris], Ephemeris]:
    return lambda e: replace(e, position_m=e.position_m * fr, velocity_mps=e.velocity_mps * fv)


def _relabel(frame: str) -> Callable[[Ephemeris], Ephemeris]:
    return lambda e: replace(e, frame=frame)


def _future(e: Ephemeris) -> Ephemeris:
    return replace(e, times_utc=e.times_utc + np.timedelta64(70 * 365, "D"))


def _huge(e: Ephemeris) -> Ephemeris:
    pos = e.position_m.copy()
    pos[len(pos) // 2, 1] = 1e300
    return replace(e, position_m=pos)


def _conflicting_epoch(e: Ephemeris) -> Ephemeris:
    """One epoch written twice, the second copy 2 km off (an interleaved record of another solution)."""
    k = len(e) // 2
    idx = np.r_[np.arange(k + 1), k, np.arange(k + 1, len(e))]
    pos = e.position_m[idx].copy()
    pos[k + 1, 0] += 2000.0
    return replace(e, times_utc=e.times_utc[idx], position_m=pos, velocity_mps=e.velocity_mps[idx])


def _time_swap(e: Ephemeris) -> Ephemeris:
    """The time tags of two neighbouring records exchanged, their states kept (epochs not monotone)."""
    t = e.times_utc.copy()
    k = len(t) // 2
    t[[k, k + 1]] = t[[k + 1, k]]
    return replace(e, times_utc=t)


def _late(e: Ephemeris) -> Ephemeris:
    t = e.times_utc.copy()
    t[len(t) // 2 :] += np.timedelta64(3, "h")
    return replace(e, times_utc=t)


def _early_overlap(e: Ephemeris) -> Ephemeris:
    """The second half tagged an hour early: its epochs interleave with the first half's other states."""
    t = e.times_utc.copy()
    t[len(t) // 2 :] -= np.timedelta64(3600 + 30, "s")
    return replace(e, times_utc=t)


def _velocity_sign(e: Ephemeris) -> Ephemeris:
    return replace(e, velocity_mps=-e.velocity_mps)


def _replace_text(old: str, new: str, count: int = 1) -> Callable[[bytes], bytes]:
    def edit(data: bytes) -> bytes:
        text = data.decode()
        assert old in text, old
        return text.replace(old, new, count).encode()

    return edit


def _sp3_stars(data: bytes) -> bytes:
    """One position written as SP3's overflow marker (a field of asterisks)."""
    lines = data.decode().split("\n")
    ks = [i for i, line in enumerate(lines) if line.startswith("P")]
    k = ks[len(ks) // 2]
    lines[k] = lines[k][:4] + "*" * 14 + lines[k][18:]
    return "\n".join(lines).encode()


def _sp3_repeat_block(data: bytes) -> bytes:
    """One epoch block (``*`` line, P and V records) written twice in a row."""
    lines = data.decode().split("\n")
    ks = [i for i, line in enumerate(lines) if line.startswith("* ")]
    k = ks[len(ks) // 2]
    return "\n".join([*lines[: k + 3], *lines[k : k + 3], *lines[k + 3 :]]).encode()


def _sp3_cut_record(data: bytes) -> bytes:
    """The ``EOF`` line gone and the last velocity record cut in the middle of a number."""
    return cut_last_line(data.replace(b"EOF", b"").rstrip())


def _csv_semicolons(data: bytes) -> bytes:
    return data.replace(b",", b";")


def _csv_interleaved_satellites(data: bytes) -> bytes:
    lines = data.decode().rstrip("\n").split("\n")
    body = [ln.replace(",L27,", ",L28,") if i % 2 else ln for i, ln in enumerate(lines[1:])]
    return ("\n".join([lines[0], *body]) + "\n").encode()


def _oem_xxe(data: bytes) -> bytes:
    text = data.decode()
    head, _, rest = text.partition("?>")
    doctype = '<!DOCTYPE oem [<!ENTITY x SYSTEM "file:///etc/hostname">]>'
    return (head + "?>\n" + doctype + rest.replace("<OBJECT_NAME>L27", "<OBJECT_NAME>&x;L27", 1)).encode()


def _beyond_moon(fmt: str) -> Callable[[Path], Run]:
    return _orbit(fmt, hours=24.0, altitude_km=420_000.0, step_s=600.0)


SP3 = cases_of(
    "hostile files: SP3",
    [
        ("sp3 CRLF line ends (control)", _orbit("sp3", edit=crlf, ok=True)),
        ("sp3 last line cut in half", _orbit("sp3", edit=cut_last_line, ok=True)),
        ("sp3 last record cut, no EOF", _orbit("sp3", edit=_sp3_cut_record, said="truncat|incomplete|missing|skipped")),
        ("sp3 empty file", _orbit("sp3", edit=empty)),
        ("sp3 header line only", _orbit("sp3", edit=header_only)),
        ("sp3 a position of asterisks", _orbit("sp3", edit=_sp3_stars, said="removed|skipped|missing|bad")),
        ("sp3 one epoch block written twice", _orbit("sp3", edit=_sp3_repeat_block, said="duplicate")),
        ("sp3 two time tags exchanged", _orbit("sp3", _time_swap, said="outlier|sorted|order|removed")),
        ("sp3 GCRF data in an ITRF file", _orbit("sp3", lambda e: replace(e, position_m=itrf_inverse(e)))),
        ("sp3 velocities reversed", _orbit("sp3", _velocity_sign)),
        ("sp3 velocities in km/s (x1e-4)", _orbit("sp3", _scaled(1.0, 1e-4), said=r"rescaled by 1e\+4")),
        ("sp3 orbit beyond the Moon", _beyond_moon("sp3")),
        ("sp3 epochs in 2078", _orbit("sp3", _future)),
    ],
)


def itrf_inverse(e: Ephemeris) -> np.ndarray:
    """The positions of an ITRF ephemeris as if they were GCRF (the ITRF->GCRF step left undone twice)."""
    r, _ = gcrf_to_itrf(e.times_utc, e.position_m, e.velocity_mps)
    return r


LATIN1_COMMENT = "COMMENT résumé of the orbit".encode("latin-1")
OEM = cases_of(
    "hostile files: OEM and navigation CSV",
    [
        ("oem UTF-8 BOM and CRLF (control)", _orbit("oem", edit=lambda d: bom(crlf(d)), ok=True)),
        ("oem Latin-1 byte in a comment", _orbit("oem", edit=latin1_line(b"CCSDS_OEM_VERS", LATIN1_COMMENT))),
        ("oem last line cut in half", _orbit("oem", edit=cut_last_line, said="skipped|truncat|malformed")),
        ("oem empty file", _orbit("oem", edit=empty)),
        ("oem positions and velocities in m and m/s", _orbit("oem", _scaled(1e3, 1e3))),
        ("oem velocities x1.5 (hyperbolic)", _orbit("oem", _scaled(1.0, 1.5))),
        ("oem velocities reversed", _orbit("oem", _velocity_sign)),
        ("oem orbit beyond the Moon", _beyond_moon("oem")),
        ("oem CENTER_NAME MOON", _orbit("oem", edit=_replace_text("CENTER_NAME = EARTH", "CENTER_NAME = MOON"))),
        ("oem REF_FRAME TEME", _orbit("oem", edit=_replace_text("REF_FRAME = GCRF", "REF_FRAME = TEME"))),
        ("oem epochs in 2078", _orbit("oem", _future)),
        ("oem across the 2016 leap second (control)", _orbit("oem", ok=True, epoch="2016-12-31T20:00:00")),
        ("sp3 across the 2016 leap second (control)", _orbit("sp3", ok=True, epoch="2016-12-31T20:00:00")),
        ("oem one epoch twice, 2 km apart", _orbit("oem", _conflicting_epoch)),
        ("oem-xml velocities in m/s", _orbit("oem-xml", _scaled(1.0, 1e3), said=r"rescaled by 1e-3")),
        ("oem-xml external entity", _orbit("oem-xml", edit=_oem_xxe)),
        ("oem-xml last line cut", _orbit("oem-xml", edit=cut_last_line)),
        ("csv UTF-8 BOM (control)", _orbit("csv", edit=bom, ok=True)),
        ("csv last line cut in half", _orbit("csv", edit=cut_last_line, said="skipped|truncat|malformed|removed")),
        ("csv header line only", _orbit("csv", edit=header_only)),
        ("csv positions in km, velocities in km/s", _orbit("csv", _scaled(1e-3, 1e-3))),
        ("csv velocities in dm/s", _orbit("csv", _scaled(1.0, 10.0), said=r"rescaled by 1e-1")),
        ("csv semicolon separated", _orbit("csv", edit=_csv_semicolons)),
        ("csv a position of 1e300", _orbit("csv", _huge, said="outlier|removed")),
        ("csv GCRF data labelled ITRF", _orbit("csv", _relabel("ITRF"))),
        ("csv two satellites interleaved", _orbit("csv", edit=_csv_interleaved_satellites)),
        ("csv epochs in 2078", _orbit("csv", _future)),
        ("csv second half 3 h late", _orbit("csv", _late, said="gap of|outlier|removed")),
        ("oem second half 1 day early (overlap)", _orbit("oem", _early_overlap)),
        ("csv two time tags exchanged", _orbit("csv", _time_swap, said="outlier|sorted|order|removed")),
    ],
)


# ------------------------------------------------------------------------------------------------ CPF


def _cpf(scale: float = 1.0, edit: Callable[[bytes], bytes] | None = None, years: int = 0) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        eph = itrf(truth_orbit(hours=24.0, altitude_km=5900.0, step_s=240.0, epoch="2018-06-14T00:00:00"))
        lines = [
            f"H1 CPF 2 HTS {2018 + years} 6 13 12 164 1 lageos1 NONE",
            f"H2 7603901 1155 8820 {2018 + years} 6 13 0 0 0 {2018 + years} 6 15 0 0 0 240 1 1 0 0 0 1",
            "H9",
        ]
        mjd0 = 58283 + round(years * 365.25)
        for t, r in zip(eph.times_utc, eph.position_m * scale, strict=True):
            sec = float((t - np.datetime64("2018-06-14", "ns")) / np.timedelta64(1, "s"))
            day, sod = divmod(sec, 86400.0)
            lines.append(f"10 0 {mjd0 + int(day)} {sod:12.5f} 0 {r[0]:14.3f} {r[1]:14.3f} {r[2]:14.3f}")
        path = folder / "lageos1.cpf"
        path.write_text("\n".join([*lines, "99"]) + "\n")
        if edit is not None:
            _rewrite(path, edit)
        return Run(["detect", "orbit", path.name, "--out", "e.csv", "--catalog", "c.sqlite"], [path.name])

    return build


def _drop_end(data: bytes) -> bytes:
    return cut_last_line(data.replace(b"\n99\n", b"\n"))


CPF = cases_of(
    "hostile files: CPF",
    [
        ("cpf positions in km", _cpf(1e-3)),
        ("cpf positions x2 (speed inconsistent with radius)", _cpf(2.0)),
        ("cpf last record cut in half", _cpf(edit=_drop_end)),
        ("cpf epochs in 2090", _cpf(years=72)),
    ],
)


# ------------------------------------------------------------------------------------------------ attitude files


def _attitude(
    edit: Callable[[bytes], bytes],
    toml_edit: Callable[[str], str | bytes] | None = None,
    said: str | None = None,
    ok: bool = False,
) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        text = THESIS_TOML.read_text()
        toml = toml_edit(text) if toml_edit else text
        (folder / "sc.toml").write_bytes(toml if isinstance(toml, bytes) else toml.encode())
        before = [["-q", "simulate", "attitude", "--duration", "600", "--telemetry-rate", "1", "--out", "t.csv"]]
        argv = ["detect", "attitude", "t.csv", "--spacecraft", "sc.toml", "--out", "e.csv", "--catalog", "c.sqlite"]
        EDITS_BYTES[f"{folder}/t.csv"] = edit
        before.append(["__bytes__", "t.csv"])
        return Run(argv, ["t.csv", "sc.toml"], names="sc.toml|t.csv", before=before, said=said, ok=ok)

    return build


#: The byte edit of each attitude case's telemetry, run by the harness after the simulation.
EDITS_BYTES: dict[str, Callable[[bytes], bytes]] = {}


def apply_bytes(folder: Path, name: str) -> None:
    _rewrite(folder / name, EDITS_BYTES.pop(f"{folder}/{name}"))


def _keep(data: bytes) -> bytes:
    return data


def _sc_folder(folder: Path) -> Run:
    run = _attitude(_keep)(folder)
    (folder / "sc.toml").unlink()
    (folder / "sc.toml").mkdir()
    run.inputs = ["t.csv"]
    return run


def _latin1_toml(text: str) -> bytes:
    return text.encode() + "# résumé (a comment written in Latin-1)\n".encode("latin-1")


def _wheel_inertia(text: str) -> str:
    return text.replace("spin_inertia_kgm2 = 0.16", "spin_inertia_kgm2 = -0.16", 1)


def _lever(text: str) -> str:
    return text.replace("lever_arm_m = 1.0", "lever_arm_m = -1.0", 1)


def _triangle(text: str) -> str:
    """Principal moments 3000, 2500 and 6000 kg m²: Izz > Ixx + Iyy, no rigid body has them."""
    return text.replace("[0.0, 0.0, 3500.0]", "[0.0, 0.0, 6000.0]", 1)


def _bus_size(text: str) -> str:
    return text.replace("size_m = [2.0, 2.0, 2.0]", "size_m = [2.0, -2.0, 2.0]", 1)


ATTITUDE = cases_of(
    "hostile files: attitude and spacecraft",
    [
        ("telemetry empty file", _attitude(empty)),
        ("telemetry header line only", _attitude(header_only)),
        ("telemetry last line cut in half", _attitude(cut_last_line, said="empty or NaN values removed")),
        ("telemetry CRLF and BOM (control)", _attitude(lambda d: bom(crlf(d)), ok=True)),
        ("spacecraft file is a folder", _sc_folder),
        ("spacecraft negative wheel inertia", _attitude(_keep, _wheel_inertia)),
        ("spacecraft negative lever arm", _attitude(_keep, _lever)),
        ("spacecraft negative bus size", _attitude(_keep, _bus_size)),
        ("spacecraft inertia breaking the triangle inequality", _attitude(_keep, _triangle)),
        ("telemetry dated 2090", _attitude(lambda d: d.replace(b"2026-01-01T", b"2090-01-01T"))),
        ("spacecraft Latin-1 byte in a comment", _attitude(_keep, _latin1_toml)),
    ],
)


# ------------------------------------------------------------------------------------------------ store, catalog, flux


def _ingest(edit: Callable[[bytes], bytes] | None = None, said: str | None = None, store: str = "store") -> Callable:
    def build(folder: Path) -> Run:
        _decoder(folder)
        archive = _archive(folder, "BIRD_day.csv", 300)
        if edit is not None:
            _rewrite(archive, edit)
        argv = ["ingest", archive.name, "--decoder", "decoder.csv", "--store", store]
        names = r"BIRD_day.csv|store|decoder|archive 1 of 1"
        return Run(argv, [archive.name, "decoder.csv"], said=said, events=None, names=names)

    return build


def _store_is_file(folder: Path) -> Run:
    run = _ingest()(folder)
    (folder / "store").write_text("not a folder\n")
    run.inputs.append("store")
    return run


def _archive_values(value: str) -> Callable[[bytes], bytes]:
    def edit(data: bytes) -> bytes:
        lines = data.decode().split("\n")
        lines[100] = lines[100].rsplit(",", 1)[0] + "," + value
        return "\n".join(lines).encode()

    return edit


def _archive_future(data: bytes) -> bytes:
    return data.replace(DAY.encode(), b"2090-03-10")


def _store_export_over(folder: Path) -> Run:
    """``store export --overwrite`` aimed at a Parquet file of the store it reads."""
    _decoder(folder)
    archive = _archive(folder, "BIRD_day.csv", 300)
    first = ["-q", "ingest", archive.name, "--decoder", "decoder.csv", "--store", "store"]
    return Run([], [archive.name], events=None, before=[first, ["__store_target__", "store"]], names="store|parquet")


def store_target(folder: Path, run: Run, store: str) -> None:
    """Aim the ``store export`` of a case at the first Parquet file of the store its preparation wrote."""
    target = str(sorted((folder / store).rglob("*.parquet"))[0].relative_to(folder))
    run.argv[:] = ["store", "export", store, "--spacecraft", "SC-B", "--out", target, "--overwrite"]
    run.inputs.append(target)


STORED = f"store/spacecraft=SC-B/day={DAY}/samples.parquet"


def _cut_store(argv: list[str]) -> Callable[[Path], Run]:
    """``argv`` run on a store whose one Parquet file was cut in half by a kill (after a first ingest)."""

    def build(folder: Path) -> Run:
        _decoder(folder)
        archive = _archive(folder, "BIRD_day.csv", 300)
        first = ["-q", "ingest", archive.name, "--decoder", "decoder.csv", "--store", "store"]
        names = r"samples\.parquet|store|archive 1 of 1"
        return Run(argv, [archive.name], events=None, before=[first, ["__truncate__", STORED]], names=names)

    return build


EVENTS_HEADER = "spacecraft,kind,detector,time_utc,dH_Nms,dv_mps\n"


def _import(rows: str | None, catalog: str = "c.sqlite", ok: bool = False) -> Callable[[Path], Run]:
    """``catalog import`` of the events header and ``rows`` (``None``: an empty file)."""

    def build(folder: Path) -> Run:
        (folder / "ev.csv").write_text("" if rows is None else EVENTS_HEADER + rows)
        return Run(["catalog", "import", "ev.csv", "--catalog", catalog], ["ev.csv"], events=None, ok=ok)

    return build


def _export_over_catalog(folder: Path) -> Run:
    (folder / "ev.csv").write_text(EVENTS_HEADER + "SC-B,strike,attitude.glr,2026-03-10T00:00:00Z,0.1,\n")
    before = [["-q", "catalog", "import", "ev.csv", "--catalog", "c.sqlite"]]
    argv = ["catalog", "export", "c.sqlite", "--catalog", "c.sqlite", "--overwrite"]
    return Run(argv, ["c.sqlite", "ev.csv"], before=before, events=None, names="c.sqlite")


def _exposure(table: str) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        (folder / "days.csv").write_text(table)
        (folder / "sc.toml").write_text((KESTREL_TOML.parent / "kestrel_surfaces.toml").read_text())
        argv = [
            "flux",
            "exposure",
            "--catalog",
            "c.sqlite",
            "--spacecraft",
            "SC-A",
            "--spacecraft-file",
            "sc.toml",
            "--table",
            "days.csv",
            "--altitude-km",
            "700",
            "--inclination-deg",
            "98.2",
            "--epoch",
            "2026",
            "--false-alarms-per-day",
            "1",
            "--dH90",
            "0.02",
        ]
        (folder / "ev.csv").write_text(EVENTS_HEADER + "SC-A,strike,attitude.glr,2026-03-10T00:00:00Z,0.1,\n")
        before = [["-q", "catalog", "import", "ev.csv", "--catalog", "c.sqlite"]]
        return Run(argv, ["days.csv", "sc.toml"], events=None, names="days.csv|sc.toml", before=before)

    return build


GOOD = "2026-03-10T00:00:00Z"
LATIN1_ROW = f"{DAY}T00:00:00.500Z,BIRD.É,1.0".encode("latin-1")
STORE = cases_of(
    "hostile files: store, catalog, flux",
    [
        ("ingest empty archive", _ingest(empty)),
        ("ingest archive last line cut in half", _ingest(cut_last_line, "last line cut")),
        ("ingest archive in Latin-1", _ingest(latin1_line(b"time", LATIN1_ROW))),
        ("ingest a value inf", _ingest(_archive_values("inf"), "removed|skipped|non-finite|inf")),
        ("ingest a value 1e308", _ingest(_archive_values("1e308"), "absurd")),
        ("ingest archive dated 2090", _ingest(_archive_future, "dated after today")),
        ("ingest --store is a file", _store_is_file),
        ("store export --overwrite onto a stored file", _store_export_over),
        ("catalog import a header line only", _import("", ok=True)),
        ("catalog import an empty file", _import(None)),
        (
            "store export of a Parquet file cut by a kill",
            _cut_store(["store", "export", "store", "--spacecraft", "SC-B", "--out", "x.csv"]),
        ),
        (
            "ingest into a day whose Parquet file was cut",
            _cut_store(["ingest", "BIRD_day.csv", "--decoder", "decoder.csv", "--store", "store"]),
        ),
        ("catalog import a time 'nan'", _import("SC-B,strike,attitude.glr,nan,0.1,\n")),
        ("catalog import an event in 2090", _import("SC-B,strike,attitude.glr,2090-03-10T00:00:00Z,0.1,\n")),
        ("catalog import a negative |dH|", _import(f"SC-B,strike,attitude.glr,{GOOD},-0.1,\n")),
        ("catalog import dv of 1e300 m/s", _import(f"SC-B,maneuver,orbit.glr,{GOOD},,1e300\n")),
        ("catalog import inf |dH|", _import(f"SC-B,strike,attitude.glr,{GOOD},inf,\n")),
        ("catalog import into itself", _import(f"SC-B,strike,attitude.glr,{GOOD},0.1,\n", catalog="ev.csv")),
        ("catalog export --overwrite onto the catalog", _export_over_catalog),
        ("flux exposure analysed fraction 1.5", _exposure("day,analysed_fraction\n2026-03-10,1.5\n")),
        ("flux exposure analysed fraction -0.2", _exposure("day,analysed_fraction\n2026-03-10,-0.2\n")),
        ("flux exposure a day 2026-02-30", _exposure("day,analysed_fraction\n2026-02-30,0.9\n")),
        ("flux exposure altitude 5e5 km", _exposure("day,analysed_fraction,altitude_km\n2026-03-10,0.9,5e5\n")),
        ("flux exposure altitude -50 km", _exposure("day,analysed_fraction,altitude_km\n2026-03-10,0.9,-50\n")),
    ],
)


def hostile_cases() -> list[Case]:
    return [*TLE, *SP3, *OEM, *CPF, *ATTITUDE, *STORE]
