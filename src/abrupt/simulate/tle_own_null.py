"""The false-alarm rate a TLE detector realises on one satellite's own noise, beside its budget.

The threshold promises a rate per satellite-year; this module measures it on the satellite itself,
without its truth: blocks of the history's quiet stretches (residuals about a running median, with
their real gaps between element sets; :func:`abrupt.simulate.tle_null.bootstrap_null_history`) are
laid on a fresh, maneuver-free orbit and the detector runs on that history at the same budget and
settings. Every detection is a false alarm; detections and exposure are counted only at gaps whose
test holds no junction between noise blocks (:func:`~abrupt.simulate.tle_null.gaps_clear_of_junctions`:
a junction joins two unrelated stretches, an artificial step). "Quiet" keeps 3 days before and 12
days after every maneuver the caller names (the operator's, or the detector's own detections).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import pandas as pd
from scipy import stats

from abrupt.detect.tle.detectors import detector_for
from abrupt.detect.tle.elements import orbit_regime
from abrupt.readers.tle import ElementHistory
from abrupt.simulate.tle_null import bootstrap_null_history, gaps_clear_of_junctions, quiet_mask
from abrupt.thresholds import DAYS_PER_YEAR, SECONDS_PER_DAY, FalseAlarmBudget


@dataclass(frozen=True)
class OwnNullRate:
    """Realised false alarms on bootstrapped histories of one satellite's quiet noise."""

    false_alarms: int
    sat_years: float
    budget_per_year: float
    histories: int

    @property
    def rate_per_year(self) -> float:
        return self.false_alarms / self.sat_years if self.sat_years > 0 else float("nan")

    @property
    def ratio(self) -> float:
        """Realised rate / budget."""
        return self.rate_per_year / self.budget_per_year

    def interval_per_year(self, level: float = 0.95) -> tuple[float, float]:
        """Exact (Garwood) Poisson interval of the rate."""
        return poisson_interval(self.false_alarms, self.sat_years, level)

    def as_dict(self) -> dict[str, Any]:
        lo, hi = self.interval_per_year()
        return {
            **asdict(self),
            "rate_per_year": self.rate_per_year,
            "ratio": self.ratio,
            "rate_95_lo": lo,
            "rate_95_hi": hi,
        }


def poisson_interval(k: int, exposure: float, level: float = 0.95) -> tuple[float, float]:
    """Exact (Garwood 1936) interval of a Poisson rate with ``k`` events in ``exposure``."""
    if not exposure > 0:
        return float("nan"), float("nan")
    alpha = 1.0 - level
    lo = 0.0 if k == 0 else float(stats.chi2.ppf(alpha / 2.0, 2 * k)) / 2.0
    hi = float(stats.chi2.ppf(1.0 - alpha / 2.0, 2 * k + 2)) / 2.0
    return lo / exposure, hi / exposure


def own_null_rate(
    history: ElementHistory,
    maneuvers_utc: Sequence[Any],
    budget: FalseAlarmBudget,
    *,
    years: float = 4.0,
    seeds: Sequence[int] = (0, 1),
    block_sets: int = 60,
    **settings: Any,
) -> OwnNullRate:
    """False alarms per satellite-year on ``len(seeds)`` bootstrapped maneuver-free histories of
    ``years`` each built from ``history``'s quiet noise (module docstring), with the detector of the
    orbit's regime at ``budget`` and ``settings``. Raises ValueError when no quiet stretch of 12 sets
    is left."""
    regime = orbit_regime(history)
    quiet = quiet_mask(history.elements["epoch_utc"], [pd.Timestamp(m) for m in maneuvers_utc])
    fa, exposure = 0, 0.0
    for seed in seeds:
        null, junctions = bootstrap_null_history(
            history, quiet, regime=regime, years=years, seed=int(seed), block_sets=block_sets
        )
        det = detector_for(null, **settings)
        run = det.detect(null, budget)
        el = null.elements
        n_gaps = len(el) - 1
        counted = gaps_clear_of_junctions(n_gaps, junctions, det.settings.window_sets)
        span_s = (el["epoch_utc"].iloc[-1] - el["epoch_utc"].iloc[0]).total_seconds()
        exposure += span_s / SECONDS_PER_DAY / DAYS_PER_YEAR * float(counted.mean())
        ev = run.events
        if len(ev):
            # every maneuver is a false alarm here; campaign rows summarise them
            found = ev.loc[(ev["statistic"] >= ev["threshold"]) & (ev["kind"] != "maneuver_campaign")]
            epochs = el["epoch_utc"].to_numpy(dtype="datetime64[ns]")
            before = pd.to_datetime(found["elset_epoch_before_utc"]).to_numpy(dtype="datetime64[ns]")
            gap = np.clip(np.searchsorted(epochs, before), 0, n_gaps - 1)
            fa += int(counted[gap].sum())
    return OwnNullRate(fa, exposure, budget.per_year, len(seeds))


@dataclass(frozen=True)
class YearRate:
    """Realised false alarms on the own null in one calendar year of the history, beside the budget."""

    year: int
    false_alarms: int
    sat_years: float
    budget_per_year: float

    @property
    def rate_per_year(self) -> float:
        return self.false_alarms / self.sat_years if self.sat_years > 0 else float("nan")

    def as_dict(self) -> dict[str, Any]:
        lo, hi = poisson_interval(self.false_alarms, self.sat_years)
        return {**asdict(self), "rate_per_year": self.rate_per_year, "rate_95_lo": lo, "rate_95_hi": hi}


def own_null_by_year(
    history: ElementHistory,
    maneuvers_utc: Sequence[Any],
    budget: FalseAlarmBudget,
    *,
    seeds: Sequence[int] = (0, 1),
    era_reach_days: float = DAYS_PER_YEAR / 2.0,
    block_sets: int = 60,
    **settings: Any,
) -> list[YearRate]:
    """The realised false-alarm rate per calendar year of ``history`` on its own null, era by era.

    Each of ``len(seeds)`` null histories spans ``history`` and draws every noise block from the quiet
    sets within ``era_reach_days`` of its own time (:func:`bootstrap_null_history` with
    ``era_reach_days``): day ``d`` of the null has the cadence and noise of day ``d`` of the history.
    The detector runs once on each whole null (its thresholds per block of the history are fitted as
    on the real one) and every detection is a false alarm, counted in the calendar year of its gap;
    exposure is the time of the gaps clear of block junctions in that year. Raises ValueError when no
    quiet stretch of 12 sets is left."""
    regime = orbit_regime(history)
    epochs = history.elements["epoch_utc"]
    quiet = quiet_mask(epochs, [pd.Timestamp(m) for m in maneuvers_utc])
    first_utc = pd.Timestamp(epochs.iloc[0])
    span_years = (epochs.iloc[-1] - epochs.iloc[0]).total_seconds() / SECONDS_PER_DAY / DAYS_PER_YEAR
    fa: dict[int, int] = {}
    exposure: dict[int, float] = {}
    for seed in seeds:
        null, junctions = bootstrap_null_history(
            history,
            quiet,
            regime=regime,
            years=span_years,
            seed=int(seed),
            block_sets=block_sets,
            era_reach_days=era_reach_days,
        )
        det = detector_for(null, **settings)
        run = det.detect(null, budget)
        el = null.elements
        t_d = (el["epoch_utc"] - el["epoch_utc"].iloc[0]).dt.total_seconds().to_numpy() / SECONDS_PER_DAY
        year_of_gap = (first_utc + pd.to_timedelta(t_d[:-1], unit="D")).year.to_numpy()
        counted = gaps_clear_of_junctions(len(el) - 1, junctions, det.settings.window_sets)
        gap_years = np.diff(t_d) / DAYS_PER_YEAR
        for y in np.unique(year_of_gap):
            in_y = year_of_gap == y
            exposure[int(y)] = exposure.get(int(y), 0.0) + float(gap_years[in_y & counted].sum())
        ev = run.events
        if len(ev):
            found = ev.loc[(ev["statistic"] >= ev["threshold"]) & (ev["kind"] != "maneuver_campaign")]
            epochs_null = el["epoch_utc"].to_numpy(dtype="datetime64[ns]")
            before = pd.to_datetime(found["elset_epoch_before_utc"]).to_numpy(dtype="datetime64[ns]")
            gap = np.clip(np.searchsorted(epochs_null, before), 0, len(el) - 2)
            for g in gap[counted[gap]]:
                fa[int(year_of_gap[g])] = fa.get(int(year_of_gap[g]), 0) + 1
    return [YearRate(y, fa.get(y, 0), exposure[y], budget.per_year) for y in sorted(exposure)]
