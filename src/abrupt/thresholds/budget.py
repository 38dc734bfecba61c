"""The false-alarm budget: one rate with its unit, converted to test levels in one place.

Every detector is given a :class:`FalseAlarmBudget` (DESIGN.md, "Detectors") and sets its threshold
for it. A budget is a Poisson rate of alarms on event-free data, stated per day, per week or per
satellite-year; the conversions below turn it into the level a threshold fit needs:

``per_sample(sample_rate_hz)``   probability that one sample of a statistic exceeds the threshold
                                 (Bennett 2022 §2.5.1 step 4: 1/day at 10 Hz is 1/864000);
``per_block(block_s)``           probability that the maximum over a block exceeds it,
                                 1 − exp(−rate·block) (GEV block maxima, Coles 2001 §3);
``per_block_first_order(block_s)`` rate·block, its first-order value (robust Gumbel fits);
``per_test(tests, per)``         probability per independent test when tests come at a known rate
                                 (a TLE gap, a tracking pass, a window of routine telemetry);
``bonferroni(n)``                the budget split evenly over ``n`` parallel statistics;
``from_per_sample(p_fa, hz)``    the other way: the per-day budget a per-sample level stands for.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np

from abrupt.units import SECONDS_PER_DAY

BudgetUnit = Literal["day", "week", "year"]

DAYS_PER_YEAR = 365.25


@dataclass(frozen=True)
class FalseAlarmBudget:
    """A false-alarm rate: ``rate`` alarms per ``per`` (``day``, ``week`` or satellite-``year``).

    >>> FalseAlarmBudget(1, "week").per_day
    0.14285714285714285
    """

    rate: float
    per: BudgetUnit = "day"

    DAYS: ClassVar[dict[str, float]] = {"day": 1.0, "week": 7.0, "year": DAYS_PER_YEAR}

    def __post_init__(self) -> None:
        if self.per not in self.DAYS:
            raise ValueError(f"false-alarm budget unit must be one of {tuple(self.DAYS)}, got {self.per!r}")
        if not (math.isfinite(self.rate) and self.rate > 0):
            raise ValueError(f"false-alarm budget must be a positive finite rate, got {self.rate!r}")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def parse(cls, text: str) -> FalseAlarmBudget:
        """Read ``"1/day"``, ``"0.1 per week"``, ``"1/year"`` (satellite-year) or a bare number (per day)."""
        m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*(?:(?:/|per)\s*(?:satellite[- ]?)?(day|week|year|yr|d|w|y))?\s*", text)
        if m is None:
            raise ValueError(f"cannot read a false-alarm budget from {text!r}; write e.g. '1/day', '1/week', '1/year'")
        unit = {"d": "day", "w": "week", "y": "year", "yr": "year"}.get(m.group(2) or "day", m.group(2) or "day")
        return cls(float(m.group(1)), unit)  # type: ignore[arg-type]

    @classmethod
    def from_per_sample(cls, p_fa: float, sample_rate_hz: float) -> FalseAlarmBudget:
        """The per-day budget of which ``p_fa`` is the per-sample level at ``sample_rate_hz`` (the
        inverse of :meth:`per_sample` below its cap of 1)."""
        return cls(p_fa * sample_rate_hz * SECONDS_PER_DAY, "day")

    # ------------------------------------------------------------------ rates
    @property
    def per_day(self) -> float:
        """Alarms per day."""
        return self.rate / self.DAYS[self.per]

    @property
    def per_year(self) -> float:
        return self.per_day * DAYS_PER_YEAR

    def expected_in_days(self, days: float) -> float:
        """Expected number of false alarms in ``days`` days of event-free data."""
        return self.per_day * days

    # ------------------------------------------------------------------ test levels
    def per_sample(self, sample_rate_hz: float) -> float:
        """Per-sample exceedance probability at ``sample_rate_hz`` (Bennett 2022 §2.5.1 step 4)."""
        if not sample_rate_hz > 0:
            raise ValueError(f"sample_rate_hz must be positive, got {sample_rate_hz}")
        return min(1.0, self.per_day / (sample_rate_hz * SECONDS_PER_DAY))

    def per_block(self, block_s: float) -> float:
        """Probability that a block of ``block_s`` seconds holds an alarm, for a Poisson rate."""
        if not block_s > 0:
            raise ValueError(f"block_s must be positive, got {block_s}")
        # 1 - exp(-λT) with numpy's exp (math.exp may differ in the last bit; the thresholds in
        # docs/results were fitted with numpy's).
        return float(1.0 - np.exp(-self.per_day * block_s / SECONDS_PER_DAY))

    def per_block_first_order(self, block_s: float) -> float:
        """λT, the expected number of alarms in a block of ``block_s`` seconds: the per-block
        probability to first order (robust block-maxima fits use it; :meth:`per_block` is exact)."""
        if not block_s > 0:
            raise ValueError(f"block_s must be positive, got {block_s}")
        return self.per_day * block_s / SECONDS_PER_DAY

    def per_test(self, tests: float, per: BudgetUnit = "day", *, cap: float = 1.0) -> float:
        """Probability per test when independent tests come at ``tests`` per ``per`` (day, week or
        satellite-year): the budget's rate in that unit over the tests, at most ``cap`` (a TLE gap
        test caps it at 0.5, beyond which a test is no test)."""
        if not tests > 0:
            raise ValueError(f"the rate of tests must be positive, got {tests}")
        return min(cap, self.per_day * self.DAYS[per] / tests)

    def bonferroni(self, n: int) -> FalseAlarmBudget:
        """This budget split evenly over ``n`` parallel statistics (the union keeps the total rate)."""
        if n < 1:
            raise ValueError(f"need at least one statistic, got {n}")
        return FalseAlarmBudget(self.rate / n, self.per)

    def __str__(self) -> str:
        return f"{self.rate:g}/{self.per}"
