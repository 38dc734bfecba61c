"""Settings of the mean-element maneuver detector and the extra columns of its events."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from abrupt.detect.tle.default_rate import DEFAULT_TLE_RATE
from abrupt.detect.tle.intervals import LAG_LEVEL
from abrupt.thresholds import FalseAlarmBudget

EXTRA_COLUMNS: tuple[str, ...] = (
    "maneuver_type",
    "z_a",
    "z_e",
    "z_n",
    "delta_a_m",
    "elset_epoch_before_utc",
    "elset_epoch_after_utc",
    "time_method",
    "regime",
    "dv_t_sigma_mps",
    "dv_n_sigma_mps",
    "campaign_id",
    "campaign_size",
    "interval_start_utc",
    "interval_end_utc",
    "burns_max",
    "z_u",
    "delta_u_m",
    "burn_count",
)

# Sets a side needs between two accepted maneuvers. LEO campaigns (orbit raising, frozen-orbit
# control) put burns two daily element sets apart; GEO station-keeping burns are weeks apart and
# its sparser sets make a two-set level fragile. Chosen on the shared histories: every LEO history
# scores the same or better with 2, every GEO history the same or better with 3 (docs/tle.md).
CAMPAIGN_SIDE_SETS = {"leo": 2, "geo": 3}

# steps inside a campaign resolved into maneuvers (abrupt.detect.tle.campaign_steps) at this fraction
# of the campaign's largest step when switched on; off by default: chosen leave-one-satellite-out on
# the modern shared histories, no fraction that adds burns keeps every history's precision
CAMPAIGN_STEP_FRACTION = 0.1

DEFAULT_TLE_BUDGET = FalseAlarmBudget.parse(DEFAULT_TLE_RATE)


@dataclass(frozen=True)
class TleDetectorConfig:
    """Settings of the mean-element detector (units in the names); ``budget`` is the false-alarm budget
    (per satellite-year by default) the threshold is set for."""

    window_sets: int = 6
    max_window_days: float = 20.0
    noise_half_window: int = 40
    peak_half_width: int = 2
    budget: FalseAlarmBudget = DEFAULT_TLE_BUDGET
    threshold: float | None = None
    threshold_method: str = "gpd"
    min_statistic: float = 3.0
    refine_time: bool = True
    time_window_sets: int = 8
    min_side_sets: int = 3
    regime: str = "auto"
    campaign_days: float = 3.0
    campaign_chain_days: float = 7.0  # maneuver_campaign events: detections chained this close
    campaign_min_side_sets: int | None = None  # None: by regime (CAMPAIGN_SIDE_SETS)
    # a gap inside a campaign whose set-to-set step of a passes the history's own null and this fraction
    # of the campaign's largest is a maneuver of its own (abrupt.detect.tle.campaign_steps); None: off
    campaign_step_fraction: float | None = None
    time_search_sets_before: int = 3
    # gains of the (a, e, normal) groups in the combined statistic, tuned leave-one-satellite-out;
    # None: each group's own null sets them (abrupt.detect.tle.group_thresholds: T_a / T_k from each
    # group's own tail away from the in-track steps; measured in docs/results/bench_tle_timing_own_null.txt,
    # it costs CryoSat-2 recall and Jason-3 precision, so it is not the default)
    group_gain: tuple[float, float, float] | None = (1.0, 0.2, 0.2)
    along_track_gain: float = 1.0
    drag_trend: str = "ndot"  # LEO a: "ndot" removes the sets' own stated decay (drag_trend_m)
    drag_median_sets: int = 5
    drag_min_decay_m_day: float = 2.0  # the drag trend only where a decays at least this fast
    # the threshold per block of the history (cadence, drag and noise change over a mission):
    # "raise" (default) keeps the whole-history threshold where a block's own is lower, "follow"
    # uses each block's own, "none" one threshold for the whole history
    threshold_follow: str = "raise"
    threshold_block_days: float = 365.25
    threshold_reach_days: float = 182.625
    # a gap between element sets longer than this ends one analysed arc and starts another: no event
    # is stated inside it (the step test's windows reach max_window_days; a longer gap holds orbit
    # changes the sets cannot place or size)
    max_bridge_days: float = 20.0
    # an interval reaches this quantile of the history's own TLE lags back (abrupt.detect.tle.intervals)
    interval_level: float = LAG_LEVEL

    def __post_init__(self) -> None:
        if self.window_sets < 2:
            raise ValueError("window_sets must be >= 2")
        if self.peak_half_width < 1:
            raise ValueError("peak_half_width must be >= 1")
        if self.regime not in ("auto", "leo", "geo"):
            raise ValueError(f"regime must be auto, leo or geo, got {self.regime!r}")
        if self.group_gain is not None and (
            any(not (g >= 0 and math.isfinite(g)) for g in self.group_gain) or len(self.group_gain) != 3
        ):
            raise ValueError("group_gain must be three finite non-negative numbers")
        if self.drag_trend not in ("none", "ndot"):
            raise ValueError(f"drag_trend must be none or ndot, got {self.drag_trend!r}")
        if self.threshold_follow not in ("none", "raise", "follow"):
            raise ValueError(f"threshold_follow must be none, raise or follow, got {self.threshold_follow!r}")
        if not (self.threshold_block_days > 0 and self.threshold_reach_days >= 0):
            raise ValueError("threshold_block_days must be positive and threshold_reach_days non-negative")
        if not (self.max_bridge_days > 0 and math.isfinite(self.max_bridge_days)):
            raise ValueError("max_bridge_days must be a finite positive number")
        if not 0.0 < self.interval_level < 1.0:
            raise ValueError(f"interval_level must lie in (0, 1), got {self.interval_level}")
        if self.campaign_step_fraction is not None and not 0.0 <= self.campaign_step_fraction <= 1.0:
            raise ValueError(f"campaign_step_fraction must lie in [0, 1] or be None, got {self.campaign_step_fraction}")
        if self.drag_median_sets < 1:
            raise ValueError("drag_median_sets must be >= 1")
        if not (self.drag_min_decay_m_day > 0 and math.isfinite(self.drag_min_decay_m_day)):
            raise ValueError("drag_min_decay_m_day must be a finite positive number")
        if not (self.along_track_gain >= 0 and math.isfinite(self.along_track_gain)):
            raise ValueError("along_track_gain must be a finite non-negative number")

    def hash_fields(self) -> dict[str, Any]:
        """The settings as the events' ``config_hash`` reads them: the budget as its rate per year."""
        out = asdict(self)
        del out["budget"]
        out["false_alarms_per_year"] = self.budget.per_year
        return out
