"""Thresholds from a false-alarm budget (DESIGN.md principle; Bennett 2022 §2.2.3, §2.4.2, §2.5.1).

A threshold is never a magic number: it is fitted to the statistic on event-free data and stated
with the false-alarm rate it was set for. Supported fits of the event-free ("null") statistic:

``gaussian``   mean + z·sd (Bennett 2022 summation filter, §2.4.2.2);
``gamma``      a Gamma fit of a non-negative statistic (Harris 2025 §3.4);
``kde``        Gaussian kernel density (Bennett 2022 CUSUM, §2.4.2.3; trade procedure §2.5.1 step 3);
``empirical``  the plain sample quantile (Bennett 2022 Shiryaev, §2.4.2.4);
``gpd``        generalised Pareto tail above a high sample quantile (peaks over threshold), for
               false-alarm probabilities far below 1/n where a KDE's tail is only its kernel.
``gev``        generalised extreme-value fit of block maxima (:func:`fit_block_maxima_threshold`):
               sets the rate of alarm *episodes* per day, which is what an operator counts, and
               handles the strong correlation of sliding-window statistics.
``chi2``       the analytic χ²(k) upper point of a statistic that is χ² in white noise
               (:func:`chi2_threshold`; matched-filter GLRT, Kalman innovations).
``robust_gaussian``  median + z·1.4826·MAD of a long series that is mostly event-free
               (:func:`robust_gaussian_threshold`).

Every fit takes the false-alarm budget either as a :class:`~abrupt.thresholds.FalseAlarmBudget`
(``budget=``, whose methods are the one conversion to per-sample and per-block levels) or as a
per-sample ``p_fa``.

Probability per sample follows Bennett 2022 §2.5.1 step 4: one false alarm per day at 10 Hz is
``p_fa = 1 / 864000``. :func:`episode_rate` counts distinct exceedance episodes, which is what an
operator experiences as "false alarms per day" when a sliding-window statistic is correlated.

The Neyman-Pearson procedure of Bennett 2022 §2.2.3 (ROC, likelihood-ratio slope at α, Eq. 2.10-2.11)
is :func:`neyman_pearson_threshold`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize, special, stats

from abrupt.thresholds.budget import SECONDS_PER_DAY, FalseAlarmBudget
from abrupt.thresholds.noise import robust_scale

FitMethod = Literal["gaussian", "gamma", "kde", "empirical", "gpd", "gev"]
FIT_METHODS: tuple[str, ...] = ("gaussian", "gamma", "kde", "empirical", "gpd", "gev")


def _per_day(p_fa: float, sample_rate_hz: float | None) -> float:
    """The per-day rate a per-sample level stands for (NaN without a sample rate)."""
    return float("nan") if sample_rate_hz is None else FalseAlarmBudget.from_per_sample(p_fa, sample_rate_hz).per_day


@dataclass(frozen=True)
class Threshold:
    """A detection threshold with the false-alarm budget it was set for.

    ``value`` is in the units of the statistic; ``p_fa`` the per-sample false-alarm probability;
    ``false_alarms_per_day`` the corresponding rate at ``sample_rate_hz`` (NaN if not given).
    """

    value: float
    p_fa: float
    method: str
    n_samples: int
    false_alarms_per_day: float = float("nan")
    sample_rate_hz: float = float("nan")

    def as_dict(self) -> dict[str, float | int | str]:
        return asdict(self)


def _clean_null(null_statistic: ArrayLike) -> NDArray[np.float64]:
    x = np.asarray(null_statistic, dtype=np.float64).ravel()
    x = x[np.isfinite(x)]
    if x.size < 10:
        raise ValueError(f"need at least 10 finite event-free samples to fit a threshold, got {x.size}")
    return x


def kde_quantile(x: NDArray[np.float64], q_upper: float, bandwidth: str | float = "scott") -> float:
    """The value v with P(X > v) = q_upper under a Gaussian kernel density of the samples x.

    The kernel survival function is the weighted mean of the Gaussian survival functions of the
    kernels; it is solved by Brent's method. Large samples keep every point of the upper 1% tail
    (weight 1) and thin the body to about 20,000 kernels (weighted up), so the tail that sets a
    small false-alarm probability is the data's, not the kernel's fall-off. The bandwidth is
    chosen on the thinned sample.
    """
    x = np.sort(x)
    # Bandwidth from a uniform thinning of the whole sample (the tail must not be over-represented).
    kde = stats.gaussian_kde(x[:: max(1, x.size // 20000)], bw_method=bandwidth)
    h = float(np.sqrt(kde.covariance[0, 0]))
    weights = np.ones(x.size)
    if x.size > 20000:
        cut = int(x.size * 0.99)
        step = int(np.ceil(cut / 20000))
        body = x[:cut:step]
        x = np.concatenate([body, x[cut:]])
        weights = np.concatenate([np.full(body.size, float(step)), np.ones(x.size - body.size)])
    log_w = np.log(weights / weights.sum())

    def log_sf(v: float) -> float:
        return float(special.logsumexp(special.log_ndtr(-(v - x) / h) + log_w))

    target = np.log(q_upper)
    lo = float(x[0])
    hi = float(x[-1]) + h
    while log_sf(hi) > target:
        hi += 2 * h + (hi - lo)
    return float(optimize.brentq(lambda v: log_sf(v) - target, lo - 10 * h, hi, xtol=1e-12 * max(1.0, abs(hi))))


def gpd_quantile(x: NDArray[np.float64], q_upper: float, tail_fraction: float = 0.02) -> float:
    """Peaks-over-threshold quantile: GPD fitted to the excesses above the (1 - tail_fraction) quantile."""
    if q_upper >= tail_fraction:
        return float(np.quantile(x, 1.0 - q_upper))
    u = float(np.quantile(x, 1.0 - tail_fraction))
    excess = x[x > u] - u
    if excess.size < 30:
        raise ValueError("too few tail samples for a generalised Pareto fit; give more event-free data")
    shape, _, scale = stats.genpareto.fit(excess, floc=0.0)
    return u + float(stats.genpareto.isf(q_upper / tail_fraction, shape, loc=0.0, scale=scale))


def _gaussian_quantile(x: NDArray[np.float64], q_upper: float) -> float:
    """mean + z·sd of a Gaussian fitted to x (Bennett 2022 §2.4.2.2)."""
    return float(np.mean(x) + stats.norm.isf(q_upper) * np.std(x, ddof=1))


def _gamma_quantile(x: NDArray[np.float64], q_upper: float) -> float:
    """Upper point of a Gamma law fitted to x shifted to be positive (Harris 2025 §3.4)."""
    shift = min(0.0, float(np.min(x))) - 1e-12
    a, loc, scale = stats.gamma.fit(x - shift, floc=0.0)
    return float(stats.gamma.isf(q_upper, a, loc=loc, scale=scale)) + shift


def _empirical_quantile(x: NDArray[np.float64], q_upper: float) -> float:
    return float(np.quantile(x, 1.0 - q_upper))


#: The value exceeded with probability ``q_upper`` under each fitted family (``gev`` fits block maxima).
UPPER_QUANTILES: dict[str, Callable[[NDArray[np.float64], float], float]] = {
    "gaussian": _gaussian_quantile,
    "gamma": _gamma_quantile,
    "kde": lambda x, q: kde_quantile(x, q),
    "empirical": _empirical_quantile,
    "gpd": lambda x, q: gpd_quantile(x, q),
}


def fit_threshold(
    null_statistic: ArrayLike,
    *,
    p_fa: float | None = None,
    sample_rate_hz: float | None = None,
    method: FitMethod = "kde",
    budget: FalseAlarmBudget | None = None,
) -> Threshold:
    """Fit the event-free statistic and return the threshold exceeded with probability ``p_fa``.

    Give either ``p_fa`` (per sample), or a ``budget`` with ``sample_rate_hz`` (the rate at which the
    statistic is evaluated). The statistic is one-sided: large values are alarms.
    """
    x = _clean_null(null_statistic)
    if p_fa is None:
        if budget is None or sample_rate_hz is None:
            raise ValueError("give p_fa, or a budget with sample_rate_hz")
        p_fa = budget.per_sample(sample_rate_hz)
    if not 0 < p_fa < 1:
        raise ValueError(f"p_fa must be in (0, 1), got {p_fa}")
    if method == "gev":
        if sample_rate_hz is None:
            raise ValueError("the gev fit needs sample_rate_hz")
        return fit_block_maxima_threshold(
            null_statistic,
            sample_rate_hz=sample_rate_hz,
            budget=FalseAlarmBudget.from_per_sample(p_fa, sample_rate_hz),
        )
    try:
        quantile = UPPER_QUANTILES[method]
    except KeyError:
        raise ValueError(f"unknown threshold method {method!r}; choose one of {FIT_METHODS}") from None
    value = quantile(x, p_fa)
    rate = _per_day(p_fa, sample_rate_hz)
    return Threshold(
        value=value,
        p_fa=float(p_fa),
        method=method,
        n_samples=int(x.size),
        false_alarms_per_day=rate,
        sample_rate_hz=float("nan") if sample_rate_hz is None else float(sample_rate_hz),
    )


def block_maxima(statistic: ArrayLike, block_samples: int) -> NDArray[np.float64]:
    """Maxima of consecutive blocks of ``block_samples`` (blocks with no finite value are skipped)."""
    stream = BlockMaxima(block_samples)
    stream.push(statistic)
    return stream.maxima


class BlockMaxima:
    """Block maxima of a statistic given piece by piece, in order: :func:`block_maxima` of the pieces joined.

    Blocks start at the first value pushed; values of an unfinished block wait for the next piece and a
    last unfinished block is left out. Memory holds one block and the maxima, whatever the length pushed.
    """

    def __init__(self, block_samples: int) -> None:
        if block_samples < 1:
            raise ValueError(f"block_samples must be positive, got {block_samples}")
        self.block_samples = int(block_samples)
        self._pending = np.empty(0)
        self._maxima: list[NDArray[np.float64]] = []

    def push(self, values: ArrayLike) -> None:
        x = np.asarray(values, dtype=np.float64).ravel()
        if self._pending.size:
            x = np.concatenate([self._pending, x])
        m = (x.size // self.block_samples) * self.block_samples
        blocks = np.where(np.isfinite(x[:m]), x[:m], -np.inf).reshape(-1, self.block_samples)
        maxima = blocks.max(axis=1)
        self._maxima.append(maxima[np.isfinite(maxima)])
        self._pending = x[m:].copy()

    @property
    def maxima(self) -> NDArray[np.float64]:
        return np.asarray(np.concatenate(self._maxima) if self._maxima else np.empty(0), dtype=np.float64)


def fit_block_maxima_threshold(
    null_statistic: ArrayLike,
    *,
    sample_rate_hz: float,
    budget: FalseAlarmBudget,
    block_s: float = 600.0,
) -> Threshold:
    """Threshold for a rate of alarm episodes per day, from a GEV fit to block maxima.

    The event-free statistic is cut into blocks of ``block_s`` seconds (longer than the detector's
    window, so block maxima are nearly independent); a generalised extreme-value distribution is
    fitted to the maxima and the threshold is the level exceeded in a block with probability
    1 − exp(−rate · block length) (:meth:`FalseAlarmBudget.per_block`), i.e. a Poisson rate of
    ``budget`` episodes.
    """
    maxima = block_maxima(null_statistic, block_samples_of(block_s, sample_rate_hz))
    return gev_threshold_from_maxima(maxima, sample_rate_hz=sample_rate_hz, budget=budget, block_s=block_s)


def block_samples_of(block_s: float, sample_rate_hz: float) -> int:
    """Samples in a block of ``block_s`` seconds (at least 2)."""
    return max(2, round(block_s * sample_rate_hz))


def gev_threshold_from_maxima(
    maxima: ArrayLike, *, sample_rate_hz: float, budget: FalseAlarmBudget, block_s: float
) -> Threshold:
    """:func:`fit_block_maxima_threshold` from the block maxima themselves (e.g. of :class:`BlockMaxima`)."""
    maxima = np.asarray(maxima, dtype=np.float64)
    block = block_samples_of(block_s, sample_rate_hz)
    if maxima.size < 20:
        raise ValueError(
            f"need at least 20 blocks of {block_s:g} s of event-free data for a GEV fit, got {maxima.size}"
        )
    shape, loc, scale = stats.genextreme.fit(maxima)
    value = float(stats.genextreme.isf(budget.per_block(block_s), shape, loc=loc, scale=scale))
    return Threshold(
        value=value,
        p_fa=budget.per_sample(sample_rate_hz),
        method="gev",
        n_samples=int(maxima.size * block),
        false_alarms_per_day=float(budget.per_day),
        sample_rate_hz=float(sample_rate_hz),
    )


def _level(p_fa: float | None, sample_rate_hz: float | None, budget: FalseAlarmBudget | None) -> float:
    """Per-sample false-alarm probability: ``p_fa`` itself, or the budget's at ``sample_rate_hz``."""
    if p_fa is not None:
        return float(p_fa)
    if sample_rate_hz is None or budget is None:
        raise ValueError("give p_fa, or a budget with sample_rate_hz")
    return budget.per_sample(sample_rate_hz)


def chi2_threshold(
    dof: int = 3,
    *,
    p_fa: float | None = None,
    sample_rate_hz: float | None = None,
    budget: FalseAlarmBudget | None = None,
) -> Threshold:
    """The χ²(``dof``) upper point exceeded with the per-sample probability of the budget.

    For a statistic that is χ²-distributed without an event: the joint matched filter's GLRT
    (3 dof, Kay 1998 §7.7), a Kalman filter's normalised innovation squared (m dof).
    """
    if dof < 1:
        raise ValueError(f"a chi-square needs at least one degree of freedom, got {dof}")
    level = _level(p_fa, sample_rate_hz, budget)
    return Threshold(
        value=float(stats.chi2.isf(level, dof)),
        p_fa=level,
        method="chi2",
        n_samples=0,
        false_alarms_per_day=_per_day(level, sample_rate_hz),
        sample_rate_hz=float("nan") if sample_rate_hz is None else float(sample_rate_hz),
    )


def robust_gaussian_threshold(
    statistic: ArrayLike, *, p_fa: float, two_sided: bool = True, sample_rate_hz: float | None = None
) -> Threshold:
    """|median| + z·σ̂ with σ̂ = 1.4826·MAD of a mostly event-free series (Hampel 1974).

    For a statistic measured on the data itself (no separate event-free data): events touch few
    samples, so the median and MAD are those of the event-free statistic. ``z`` is the Gaussian upper
    ``p_fa/2`` point (two-sided) or ``p_fa`` point. ``p_fa`` is per sample.
    """
    x = np.asarray(statistic, dtype=np.float64).ravel()
    x = x[np.isfinite(x)]
    if x.size < 10:
        raise ValueError("need at least 10 finite values to set a threshold")
    z = float(stats.norm.isf(p_fa / 2.0 if two_sided else p_fa))
    med = float(np.median(x))
    sd = float(robust_scale(x))
    return Threshold(
        value=abs(med) + z * sd,
        p_fa=float(p_fa),
        method="robust_gaussian",
        n_samples=int(x.size),
        false_alarms_per_day=_per_day(p_fa, sample_rate_hz),
        sample_rate_hz=float("nan") if sample_rate_hz is None else float(sample_rate_hz),
    )


def qq_points(
    null_statistic: ArrayLike, method: FitMethod = "gaussian", n_points: int = 200
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Q-Q diagnostic: (theoretical quantiles of the fitted family, sample quantiles).

    Points on the diagonal mean the family fits; a sample tail above the diagonal means the fit
    under-states the false-alarm rate there (Bennett 2022 Fig. 2.17).
    """
    x = np.sort(_clean_null(null_statistic))
    probs = (np.arange(1, n_points + 1) - 0.5) / n_points
    sample_q = np.quantile(x, probs)
    if method == "gaussian":
        theo = stats.norm.ppf(probs, loc=np.mean(x), scale=np.std(x, ddof=1))
    elif method == "gamma":
        shift = min(0.0, float(x[0])) - 1e-12
        a, loc, scale = stats.gamma.fit(x - shift, floc=0.0)
        theo = stats.gamma.ppf(probs, a, loc=loc, scale=scale) + shift
    elif method in ("kde", "empirical", "gpd"):
        kde = stats.gaussian_kde(x[:: max(1, x.size // 20000)])
        draws = kde.resample(200000, seed=np.random.default_rng(0)).ravel()
        theo = np.quantile(draws, probs)
    else:
        raise ValueError(f"unknown method {method!r}")
    return np.asarray(theo, dtype=np.float64), np.asarray(sample_q, dtype=np.float64)


def roc_curve(
    null_statistic: ArrayLike, event_statistic: ArrayLike, n_points: int = 400
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Empirical ROC: (thresholds, P_FA, P_D) from event-free and with-event statistic samples."""
    x0 = np.sort(_clean_null(null_statistic))
    x1 = np.sort(_clean_null(event_statistic))
    lo, hi = min(x0[0], x1[0]), max(x0[-1], x1[-1])
    thr = np.linspace(lo, hi, n_points)
    p_fa = 1.0 - np.searchsorted(x0, thr, side="right") / x0.size
    p_d = 1.0 - np.searchsorted(x1, thr, side="right") / x1.size
    return thr, p_fa, p_d


def neyman_pearson_threshold(
    null_statistic: ArrayLike, event_statistic: ArrayLike, alpha: float
) -> tuple[float, float]:
    """Bennett 2022 §2.2.3 (Eqs. 2.10-2.11): likelihood-ratio threshold at P_FA = alpha.

    Kernel densities p0, p1 are fitted to the event-free and with-event statistics. The ROC slope
    dP_D/dP_FA at P_FA = alpha equals the likelihood ratio tau = p1(y_a)/p0(y_a) at the statistic
    value y_a whose null exceedance is alpha; returns (y_thresh, tau). For a monotone likelihood
    ratio y_thresh equals the alpha-quantile threshold of the null, the cross-check the spec gives.
    """
    x0 = _clean_null(null_statistic)
    x1 = _clean_null(event_statistic)
    y_alpha = kde_quantile(x0, alpha)
    k0 = stats.gaussian_kde(x0[:: max(1, x0.size // 20000)])
    k1 = stats.gaussian_kde(x1[:: max(1, x1.size // 20000)])
    log_tau = float(k1.logpdf(y_alpha)[0] - k0.logpdf(y_alpha)[0])
    return y_alpha, float(np.exp(min(log_tau, 700.0)))


def episode_rate(
    statistic: ArrayLike, threshold: float, *, sample_rate_hz: float, min_separation_samples: int
) -> tuple[int, float]:
    """Count exceedance episodes (runs above threshold, merged when closer than the separation).

    Returns (episodes, episodes per day). A sliding-window statistic exceeds its threshold for many
    consecutive samples around one event; an operator sees one alarm, so this is the rate to report.
    """
    s = np.asarray(statistic, dtype=np.float64)
    above = np.flatnonzero(s > threshold)
    if above.size == 0:
        episodes = 0
    else:
        episodes = 1 + int(np.count_nonzero(np.diff(above) > min_separation_samples))
    days = s.size / (sample_rate_hz * SECONDS_PER_DAY)
    return episodes, episodes / days if days > 0 else float("nan")


def gpd_return_level_upper(x: NDArray[np.float64], p_fa: float, *, tail_fraction: float, z: float = 1.0) -> float:
    """Upper confidence bound of the value exceeded with probability ``p_fa`` per sample (peaks over the
    (1 − ``tail_fraction``) quantile u, generalised Pareto excesses with scale σ and shape ξ).

    Return level (Coles 2001, Eq. 4.12): x_p = u + σ/ξ·(r^ξ − 1), r = tail_fraction/p_fa (→ u + σ ln r as
    ξ → 0). Its variance by the delta method, ∇x_pᵀ V ∇x_p, with the asymptotic covariance of the ML fit of
    n excesses V = (1+ξ)/n·[[2σ², σ], [σ, 1+ξ]] (Smith 1987, valid for ξ > −1/2; ξ is floored at −0.45
    for V). Returns x_p + z·sd(x_p); z = 0 gives the point estimate (:func:`abrupt.thresholds.gpd_quantile`).
    """
    x = np.asarray(x, dtype=np.float64)
    if p_fa >= tail_fraction:
        return float(np.quantile(x, 1.0 - p_fa))
    u = float(np.quantile(x, 1.0 - tail_fraction))
    excess = x[x > u] - u
    if excess.size < 30:
        raise ValueError("too few tail samples for a generalised Pareto fit; give more event-free data")
    xi, _, sigma = stats.genpareto.fit(excess, floc=0.0)
    r = tail_fraction / p_fa
    log_r = float(np.log(r))
    if abs(xi) < 1e-6:
        level = u + sigma * log_r
        grad = np.array([log_r, 0.5 * sigma * log_r**2])
    else:
        rx = r**xi
        level = u + sigma / xi * (rx - 1.0)
        grad = np.array([(rx - 1.0) / xi, -sigma / xi**2 * (rx - 1.0) + sigma / xi * rx * log_r])
    if z == 0.0:
        return float(level)
    xe = max(float(xi), -0.45)
    cov = (1.0 + xe) / excess.size * np.array([[2.0 * sigma**2, sigma], [sigma, 1.0 + xe]])
    return float(level + z * np.sqrt(max(0.0, float(grad @ cov @ grad))))
