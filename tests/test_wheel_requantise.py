"""Wheel-speed changes added to tachometer counts keep the archive's own quantisation.

Independent truths: the exact count of a known pulse phase, ⌊P_k + Δφ_k⌋ − ⌊P_{k−1} + Δφ_{k−1}⌋, and the
input samples themselves (untouched samples must come back bit for bit, and the count noise far from
the injections must be the input's, however many injections there are).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from abrupt.model.flight_config import FlightChannel, Tachometer
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import ingest_archives
from abrupt.series.timetable import NS
from abrupt.simulate.confounders import Confounder, inject_confounders
from abrupt.simulate.injection import InjectedStrike, inject_strikes, requantised_wheel
from abrupt.store import TelemetryStore
from flight_synth import make_archive

TACH = Tachometer(pulses_per_rev=64.0, gate_s=1.0)


def test_requantised_counts_are_the_exact_counts_of_the_shifted_phase() -> None:
    rng = np.random.default_rng(5)
    ch = FlightChannel("W1", "wheel_speed", 0, "counts", tachometer=TACH)
    t = np.arange(4000.0)
    phase = rng.uniform() + 150.3 * t + 40.0 * np.sin(2 * math.pi * t / 3000.0)  # pulses, smooth speed
    counts = np.diff(np.floor(phase), prepend=math.floor(phase[0] - 150.3))
    d_omega = np.where(t >= 1000.0, 0.37 * (1.0 - np.exp(-(t - 1000.0) / 20.0)), 0.0)  # rad/s, lasting
    d_phase = np.cumsum(d_omega * TACH.gate_s) * TACH.pulses_per_rev / (2 * math.pi)
    exact = np.diff(np.floor(phase + d_phase), prepend=math.floor(phase[0] - 150.3))
    got = requantised_wheel(ch, counts, d_omega)
    assert np.array_equal(got[t < 1000.0], counts[t < 1000.0])  # untouched: bit for bit
    assert np.mean(got == exact) > 0.95  # an independent random quantisation phase matches ~70 %
    assert np.abs(np.cumsum(got - exact)).max() <= 1.0  # the pulse total never drifts
    far = t > 2000.0
    assert np.std(np.diff(got[far])) == pytest.approx(np.std(np.diff(exact[far])), rel=0.05)


def test_requantised_without_tachometer_adds_the_change_as_it_is() -> None:
    ch = FlightChannel("W1", "wheel_speed", 0, "rad/s")
    x = np.linspace(100.0, 101.0, 50)
    d = np.linspace(0.0, 0.2, 50)
    assert np.allclose(requantised_wheel(ch, x, d), x + d)


@pytest.fixture(scope="module")
def synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    d = tmp_path_factory.mktemp("requant")
    a = make_archive(d, hours=3.0, strikes=[])
    ingest_archives([a.archive], a.decoder, d / "store")
    return d, a


def test_many_injections_leave_untouched_wheel_samples_and_the_count_noise_as_they_were(
    synth: tuple[Path, object],
) -> None:
    d, a = synth
    sc = load_spacecraft(a.spacecraft)  # type: ignore[attr-defined]
    t0 = int(a.start.astype(np.int64))  # type: ignore[attr-defined]
    raw = TelemetryStore(d / "store").read_range(
        sc.name, np.datetime64(t0, "ns"), np.datetime64(t0 + int(3 * 3600 * NS), "ns")
    )
    leaks = [
        Confounder("thruster_leak", t0 + int((1800 + 400 * k) * NS), "thruster",
                   {"torque_B_Nm": [3e-4, -2e-4, 1e-4 * (k + 1)], "duration_s": 120.0})
        for k in range(5)
    ]  # fmt: skip
    strikes = [InjectedStrike(t0 + int((2000 + 400 * k) * NS), np.array([0.04, -0.03, 0.05])) for k in range(5)]
    out = inject_strikes(inject_confounders(raw, sc, leaks), sc, strikes, response="linear")
    t = raw["time"].to_numpy().astype("datetime64[ns]").astype(np.int64)
    for ch in sc.flight.of("wheel_speed"):  # type: ignore[union-attr]
        m = (raw["mnemonic"] == ch.mnemonic).to_numpy()
        before = m & (t < t0 + 1790 * NS)
        assert np.array_equal(out["value"].to_numpy()[before], raw["value"].to_numpy()[before])
        far = t[m][1:] >= t0 + int(2.5 * 3600 * NS)  # > 40 min after the last injection
        noise_in = np.std(np.diff(raw["value"].to_numpy()[m])[far])
        noise_out = np.std(np.diff(out["value"].to_numpy()[m])[far])
        assert noise_out == pytest.approx(noise_in, rel=0.1)
        assert not np.array_equal(out["value"].to_numpy()[m], raw["value"].to_numpy()[m])
