"""A wheel's speed reading, its jump statistics and their threshold: a counter's quantisation is bounded.

A tachometer counts the pulses of a wheel's encoder over a gate: its reading is ⌊P_end⌋ − ⌊P_start⌋ of the
pulse phase P times the quantum q = 2π / (pulses per revolution · gate), so each reading is the speed (with
its own continuous noise) plus an error within one quantum. Two linear statistics of the readings look for
jumps (a miscount: one reading off by N pulses and back; a glitch: a reading that moved and stayed): their
quantisation part is bounded by q Σ |a| and only their continuous part has a tail (:func:`wheel_threshold`).
On a coarse counter whose speed has little noise the statistic is lattice-valued and an exponential tail
fitted through its few levels says nothing about what lies beyond them; on a fine or unquantised reading the
bound is small and the usual tail fit holds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from abrupt.detect.attitude.tail_fit import TAIL_COUNTS, floored_threshold, robust_sigma
from abrupt.model.flight_config import Tachometer
from abrupt.types import FloatArray

#: Samples of the step statistic's trend: the mean first difference over this many, centred.
STEP_WINDOW = 11
#: Coefficients a (offset from sample k → weight) of the two wheel statistics s_k = Σ a_j x_(k+j): the step
#: (the mean of samples k+1, k+2 against the mean of k−1, k, less twice the mean first difference over
#: ``STEP_WINDOW``: a reading that moved by G and stayed gives G (1 − 2/``STEP_WINDOW``), one that came back
#: G/2) and the pair (sample k+1 against the mean of its two neighbours: a one-sample miscount of N pulses
#: gives N quanta).
STEP_COEFFS = {
    -(STEP_WINDOW // 2): 2.0 / STEP_WINDOW,
    -1: -0.5,
    0: -0.5,
    1: 0.5,
    2: 0.5,
    STEP_WINDOW // 2 + 1: -2.0 / STEP_WINDOW,
}
PAIR_COEFFS = {0: -0.5, 1: 1.0, 2: -0.5}
#: The trimmed second moment of a statistic that estimates its continuous part ignores values beyond its
#: quantisation bound plus this many of its quantisation's standard deviations (faults, strikes).
MOMENT_CUT = 2.0
#: Passes of the wheel threshold's estimate of its continuous part, each without the jumps above the last.
MOMENT_PASSES = 3


@dataclass(frozen=True)
class WheelReading:
    """How a wheel channel reads its speed: the tachometer's quantum q [rad/s] (0: an unquantised reading)
    and the lag of its gate in samples when the gate is a whole number m ≥ 1 of sample intervals (the gate
    of sample k then opens where the gate of sample k − m closed, so their quantisation errors share a
    phase), else None."""

    quantum_rad_s: float = 0.0
    gate_lag: int | None = None


def quantisation_bound(coeffs: dict[int, float], quantum: float) -> float:
    """Bound [rad/s] of the quantisation part of s = Σ a_j x_j: each reading's error is within one quantum
    (a counter's reading is ⌊P_end⌋ − ⌊P_start⌋ of the pulse phase P, its error the difference of two
    fractions in [0, 1); a rounded one's is within half), so |Σ a_j ε_j| < q Σ |a_j|."""
    return quantum * sum(abs(a) for a in coeffs.values())


def quantisation_variance(coeffs: dict[int, float], reading: WheelReading) -> float:
    """Variance [(rad/s)²] of the quantisation part of s = Σ a_j x_j for a counter whose phase fractions are
    independent and uniform on [0, 1) (variance 1/12; a wheel whose speed sweeps many pulses per sample over
    a day): reading j's error is q (u_start,j − u_end,j), so Σ a_j ε_j = q Σ c_i u_i over the distinct phase
    instants; with a gate of m samples the start of j is the end of j − m (c_i = a_(i+m) − a_i), otherwise
    every instant is its own (Σ c² = 2 Σ a²)."""
    q = reading.quantum_rad_s
    if reading.gate_lag is None:
        return q * q / 12.0 * 2.0 * sum(a * a for a in coeffs.values())
    m = reading.gate_lag
    c: dict[int, float] = {}
    for j, a in coeffs.items():
        c[j] = c.get(j, 0.0) - a  # the gate's end at sample j
        c[j - m] = c.get(j - m, 0.0) + a  # its start, the end of sample j − m
    return q * q / 12.0 * sum(v * v for v in c.values())


def _apply(coeffs: dict[int, float], x: FloatArray) -> FloatArray:
    """s_k = Σ a_j x_(k+j) for k = 0 … n − 2 (element k between samples k and k+1); NaN where it reaches
    past the ends."""
    n = x.size
    out = np.zeros(n - 1)
    for j, a in coeffs.items():
        idx = np.arange(n - 1) + j
        inside = (idx >= 0) & (idx < n)
        out += a * np.where(inside, x[np.clip(idx, 0, n - 1)], np.nan)
    return out


def wheel_statistics(speed_rad_s: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(step, pair) [rad/s] of a wheel's raw speed, element k between samples k and k+1: the step is
    (x_(k+1) + x_(k+2))/2 − (x_(k−1) + x_k)/2 less twice the mean first difference over ``STEP_WINDOW``
    samples centred on it (a wheel's steady acceleration taken out), the pair x_(k+1) − (x_k + x_(k+2))/2
    (a reading off by N and back: N). Both are linear in the readings (``STEP_COEFFS``, ``PAIR_COEFFS``),
    so a quantised reading's error passes through them bounded (:func:`quantisation_bound`)."""
    x = np.asarray(speed_rad_s, dtype=np.float64)
    return np.abs(_apply(STEP_COEFFS, x)), np.abs(_apply(PAIR_COEFFS, x))


def wheel_jump_statistic(speed_rad_s: FloatArray, reading: WheelReading | None = None) -> tuple[FloatArray, float]:
    """Jumps of a wheel's raw speed [σ], element k between samples k and k+1: the larger of the step and the
    pair of :func:`wheel_statistics` over σ, the larger of the step's robust scale and its quantisation's
    standard deviation (:func:`quantisation_variance`). Returns (statistic, σ [rad/s])."""
    reading = reading or WheelReading()
    step, pair = wheel_statistics(speed_rad_s)
    quant = math.sqrt(quantisation_variance(STEP_COEFFS, reading))
    sigma = max(robust_sigma(_apply(STEP_COEFFS, np.asarray(speed_rad_s, dtype=np.float64))), quant, 1e-12)
    return np.fmax(step, pair) / sigma, sigma


def continuous_sigma(s: FloatArray, coeffs: dict[int, float], reading: WheelReading) -> float:
    """Standard deviation [rad/s] of the continuous part of a wheel statistic s (the noise of the speed
    itself, before the counter): its second moment, over the values below the quantisation bound plus
    ``MOMENT_CUT`` of the quantisation's standard deviation, less the quantisation's variance; 0 when the
    quantisation explains it all."""
    v = s[np.isfinite(s)]
    if v.size == 0:
        return 0.0
    var_q = quantisation_variance(coeffs, reading)
    cut = quantisation_bound(coeffs, reading.quantum_rad_s) + MOMENT_CUT * math.sqrt(var_q)
    m2 = float(np.sum(np.where(v < cut, v * v, 0.0))) / v.size
    return math.sqrt(max(m2 - var_q, 0.0))


def wheel_threshold(step: FloatArray, pair: FloatArray, reading: WheelReading, p_sample: float, sigma: float) -> float:
    """Threshold [σ] of :func:`wheel_jump_statistic` for a per-sample false-alarm probability ``p_sample``.

    A wheel statistic s = Σ a_j x_j of readings x = v + n + ε (the speed, a continuous noise, the counter's
    quantisation) is s = c + e with a continuous part c = Σ a_j (v + n)_j and a quantisation part |e| < B
    (:func:`quantisation_bound`), so P(|s| > B + t) ≤ P(|c| > t): beyond B the tail is the continuous
    part's (for a Laplace c exactly exponential, P(s > u) = ½ e^(−u/β) E[e^(e/β)]), and below B the shape
    is the counter's, whose levels say nothing about the tail (an exponential fitted through them
    extrapolates to many times the bound). So:

    * where the continuous part reaches beyond B often (at least ``TAIL_COUNTS[0]`` samples of the larger
      of step and pair beyond the larger bound, as for an unquantised or finely quantised reading, q = 0
      giving B = 0), the exponential tail is fitted there (:func:`tail_threshold` on levels all beyond B);
    * otherwise the bound plus a Laplace tail of the continuous part's standard deviation σ_c
      (:func:`continuous_sigma`, the larger of step's and pair's): P(|c| > t) = e^(−√2 t/σ_c), each of the
      two statistics at half of ``p_sample``: u = B + σ_c ln(2/p) / √2. A Gaussian c falls faster. The
      jumps above u (faults, strikes: ±2 samples) are left out of σ_c and u found again, at most
      ``MOMENT_PASSES`` times.

    With no continuous noise u is the step's bound B = (2 + 4/11) q plus the tail of σ_c's sampling noise
    (a few hundredths of a quantum on a day), and a miscount of N pulses gives a pair of N + e/2 quanta with
    e the counts' second difference, an integer with |e| ≤ 3: every N ≥ 5 is found (N − 3/2 > u while
    u < 3.5 q), N = 3 when e ≥ 0 or so, about half the time."""
    z = np.fmax(step, pair)
    q = reading.quantum_rad_s
    bound = max(quantisation_bound(STEP_COEFFS, q), quantisation_bound(PAIR_COEFFS, q))
    if int(np.sum(z > bound)) >= TAIL_COUNTS[0]:
        return floored_threshold(z[np.isfinite(z)] / sigma, p_sample)
    keep = np.isfinite(z)
    u = bound
    for _ in range(MOMENT_PASSES):
        sig_c = max(
            continuous_sigma(step[keep], STEP_COEFFS, reading), continuous_sigma(pair[keep], PAIR_COEFFS, reading)
        )
        u = bound + sig_c * math.log(2.0 / max(p_sample, 1e-300)) / math.sqrt(2.0)
        out = np.convolve((z > u).astype(np.float64), np.ones(5), "same") > 0
        if not (keep & out).any():
            break
        keep &= ~out
    return u / sigma


def wheel_reading(tachometer: Tachometer | None, dt_s: float) -> WheelReading:
    """The :class:`WheelReading` of a channel sampled every ``dt_s``: its quantum, and its gate's lag when the
    gate is a whole number of sample intervals."""
    if tachometer is None:
        return WheelReading()
    m = tachometer.gate_s / dt_s if dt_s > 0 else 0.0
    lag = round(m) if round(m) >= 1 and abs(m - round(m)) < 0.01 * m else None
    return WheelReading(tachometer.quantum_rad_s, lag)
