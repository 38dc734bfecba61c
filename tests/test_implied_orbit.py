"""The implied-speed check of tracking files: a range in the wrong unit is refused, real arcs pass.

Truths: vis-viva on the set-up file's own a-priori orbit (the implied speeds of the real W3B arc against
the speeds that orbit has at the same radii), and simulated tracking of known orbits (with the thesis's
noisy angles) for the orbits no real file here covers.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from abrupt.cli.main import main
from abrupt.errors import InputError, RepairLog
from abrupt.model.implied_orbit import check_implied_speeds, implied_speeds, implied_states
from abrupt.model.orbit import MU_EARTH_M3_S2
from abrupt.model.stations import ascension
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.pipelines.tracking import read_tracking_arrays
from abrupt.readers.aer import read_aer
from abrupt.readers.orekit_od_input import read_od_input
from abrupt.readers.tdm import write_tdm
from abrupt.simulate.tracking import OrbitCase, TrackingScenario, simulate_tracking

RANGE_LINE = re.compile(r"^(\S+\s+RANGE\s+\S+\s+)(\S+)", re.MULTILINE)


def _scaled_ranges(src: Path, dst: Path, factor: float) -> Path:
    """The .aer file with every range multiplied by ``factor`` (angles untouched)."""
    return _scaled_ranges_text(src.read_text(), dst, factor)


def _arrays(path: Path, setup_path: Path) -> TrackingArrays:
    setup = read_od_input(setup_path)
    return read_tracking_arrays(path, setup, refraction=setup.refraction_correction, repairs=RepairLog(str(path)))


def test_the_real_w3b_arc_passes_and_moves_as_its_a_priori_orbit_says(shared_data: Path) -> None:
    """W3B's transfer orbit (perigee 220 km above the surface: its apogee speed only 1.5 % above the least
    orbital speed) passes; each station's implied speeds match vis-viva on the set-up's a-priori orbit at
    the same radii (median within 3 %: angle noise and the chord approximation)."""
    aer, setup_path = shared_data / "tracking" / "W3B.aer", shared_data / "tracking" / "od_test_W3.in"
    data = _arrays(aer, setup_path)  # no error
    x0 = read_od_input(setup_path).initial_state
    energy = float(np.dot(x0[3:], x0[3:])) / 2 - MU_EARTH_M3_S2 / float(np.linalg.norm(x0[:3]))
    states = implied_states(data)
    assert set(states) == {"CastleRock", "Fucino", "Kumsan", "Pretoria", "Uralla"}
    for name, (r, v) in states.items():
        assert len(r) >= 20, name
        radius = np.linalg.norm(r, axis=1)
        expected = np.sqrt(2 * (energy + MU_EARTH_M3_S2 / radius))
        assert np.median(np.linalg.norm(v, axis=1) / expected) == pytest.approx(1.0, abs=0.03), name
    for s in implied_speeds(data).values():
        assert s.to_minimum > 1.0 and s.to_escape < 1.0 and not s.too_slow and not s.too_fast


def test_ranges_a_tenth_of_the_real_ones_are_refused_naming_file_and_station(shared_data: Path, tmp_path: Path) -> None:
    """Ranges ×0.1 put W3B a few thousand km above each station, turning with the Earth at a tenth of the
    least orbital speed. The reader alone accepts them (every range is a possible range)."""
    bad = _scaled_ranges(shared_data / "tracking" / "W3B.aer", tmp_path / "W3B_tenth.aer", 0.1)
    assert len(read_aer(bad)) > 0
    with pytest.raises(InputError, match=r"W3B_tenth\.aer: column 'range': station \w+: .* least speed") as exc:
        _arrays(bad, shared_data / "tracking" / "od_test_W3.in")
    assert "\n" not in str(exc.value)
    ratio = float(re.search(r"speed of ([0-9.]+)", str(exc.value)).group(1))  # type: ignore[union-attr]
    assert ratio < 0.2


def test_ranges_ten_times_the_real_ones_are_refused_as_escaping(shared_data: Path, tmp_path: Path) -> None:
    bad = _scaled_ranges(shared_data / "tracking" / "W3B.aer", tmp_path / "W3B_ten.aer", 10.0)
    assert len(read_aer(bad)) > 0
    with pytest.raises(InputError, match=r"W3B_ten\.aer: column 'range': station \w+: .* escape speed"):
        _arrays(bad, shared_data / "tracking" / "od_test_W3.in")


def test_a_tdm_with_ranges_a_tenth_is_refused(shared_data: Path, tmp_path: Path) -> None:
    bad = _scaled_ranges(shared_data / "tracking" / "W3B.aer", tmp_path / "tenth.aer", 0.1)
    tdm = tmp_path / "W3B_tenth.tdm"
    write_tdm(read_aer(bad), tdm, spacecraft="W3B")
    with pytest.raises(InputError, match=r"W3B_tenth\.tdm: .* least speed"):
        _arrays(tdm, shared_data / "tracking" / "od_test_W3.in")
    good = tmp_path / "W3B.tdm"
    write_tdm(read_aer(shared_data / "tracking" / "W3B.aer"), good, spacecraft="W3B")
    _arrays(good, shared_data / "tracking" / "od_test_W3.in")


def test_detect_tracking_refuses_a_range_in_the_wrong_unit_in_one_line(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = _scaled_ranges(shared_data / "tracking" / "W3B.aer", tmp_path / "W3B_tenth.aer", 0.1)
    with pytest.raises(SystemExit) as exit_:
        main(["detect", "tracking", str(bad), "--setup", str(shared_data / "tracking" / "od_test_W3.in"),
              "--out", str(tmp_path / "ev.csv"), "--catalog", str(tmp_path / "c.sqlite")])  # fmt: skip
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "least speed of an orbit" in err and "\n" not in err
    assert not (tmp_path / "ev.csv").exists()


def _simulated(case: OrbitCase, scale: float = 1.0) -> TrackingArrays:
    """Thesis-noise tracking (0.02 rad angles, 5 m ranges, 5 s cadence) of ``case`` from Ascension."""
    sim = simulate_tracking(TrackingScenario(orbit=case, duration_s=3 * case.period_s(MU_EARTH_M3_S2)), seed=1)
    meas = sim.measurements.copy()
    meas["range_m"] *= scale
    return TrackingArrays(meas, {"ASCENSION": ascension()}, epoch_utc=sim.epoch_utc)


@pytest.mark.parametrize("perigee_km", [200.0, 1000.0])
def test_a_low_orbit_with_noisy_angles_passes_and_its_tenth_is_refused(perigee_km: float) -> None:
    """The hardest real case for the lower bound is a low, nearly circular orbit (its speed is within
    1 % of the least at 200 km) seen with the thesis's 0.02 rad angle noise: it passes (noise makes a
    speed larger, never smaller), and the same measurements with ranges ×0.1 are refused."""
    r_p = 6378137.0 + perigee_km * 1e3
    case = OrbitCase(a_m=r_p / (1 - 0.02), e=0.02, i_deg=5.0)
    check_implied_speeds(_simulated(case), "sim.tdm")
    (speeds,) = implied_speeds(_simulated(case)).values()
    assert speeds.to_minimum > 1.0 and speeds.to_escape < 1.0 / math.sqrt(2) * 1.05
    with pytest.raises(InputError, match=r"sim\.tdm: .*station ASCENSION.* least speed"):
        check_implied_speeds(_simulated(case, 0.1), "sim.tdm")


def _range_only(src: Path, dst: Path, factor: float) -> Path:
    """The .aer file without its angle lines, every range multiplied by ``factor``."""
    lines = [line for line in src.read_text().splitlines() if " AZ_EL " not in line]
    return _scaled_ranges_text("\n".join(lines) + "\n", dst, factor)


def _scaled_ranges_text(text: str, dst: Path, factor: float) -> Path:
    dst.write_text(RANGE_LINE.sub(lambda m: f"{m.group(1)}{float(m.group(2)) * factor:.4f}", text))
    return dst


def test_ranges_without_angles_are_held_against_the_a_priori_orbit(shared_data: Path, tmp_path: Path) -> None:
    """Without angles no speed can be implied; W3B's ranges alone pass against the set-up's a-priori orbit
    (two-body from its state predicts them within 0.2 %), a tenth or ten times of them are refused (the fit
    would otherwise end in an unrelated error about thresholds)."""
    aer, setup = shared_data / "tracking" / "W3B.aer", shared_data / "tracking" / "od_test_W3.in"
    data = _arrays(_range_only(aer, tmp_path / "ranges.aer", 1.0), setup)
    assert implied_speeds(data) == {}  # nothing for the speed check to judge
    for factor, name in ((0.1, "tenth"), (10.0, "ten")):
        bad = _range_only(aer, tmp_path / f"ranges_{name}.aer", factor)
        with pytest.raises(InputError, match=rf"ranges_{name}\.aer: column 'range': station \w+: its ranges are"):
            _arrays(bad, setup)


def test_an_a_priori_of_another_orbit_is_refused(shared_data: Path, tmp_path: Path) -> None:
    """The same check seen from the other side: W3B's real ranges against a LEO a-priori state."""
    setup = (shared_data / "tracking" / "od_test_W3.in").read_text()
    leo = setup.replace("orbit.cartesian.px = -40517522.9", "orbit.cartesian.px = -6878137.0")
    leo = leo.replace("orbit.cartesian.py = -10003079.9", "orbit.cartesian.py = 0.0")
    leo = leo.replace("orbit.cartesian.vx = 762.559", "orbit.cartesian.vx = 0.0")
    leo = leo.replace("orbit.cartesian.vy =  -1474.468", "orbit.cartesian.vy = -7612.6")
    assert leo != setup
    (tmp_path / "leo.in").write_text(leo)
    ranges = _range_only(shared_data / "tracking" / "W3B.aer", tmp_path / "ranges.aer", 1.0)
    with pytest.raises(InputError, match="a-priori orbit of another satellite"):
        _arrays(ranges, tmp_path / "leo.in")
