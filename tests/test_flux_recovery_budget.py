"""An injection-recovery table states the false-alarm budget it was made at; its efficiency is refused
for a detection run at another budget (a lower threshold recovers more, so the flux would come out low)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from abrupt.errors import InputError
from abrupt.flux.exposure import EfficiencyCurve, efficiency_per_day

DAYS = ["2026-01-01"]


def _table(per_day: float | None) -> pd.DataFrame:
    rng = np.random.default_rng(7)
    sizes = np.exp(rng.uniform(math.log(1e-3), math.log(0.1), 2000))
    found = rng.random(sizes.size) < EfficiencyCurve(0.01, 6.0)(sizes)
    table = pd.DataFrame({"day": DAYS[0], "dH_Nms": sizes, "found": found})
    if per_day is not None:
        table["false_alarms_per_day"] = per_day
    return table


def test_a_table_made_at_another_budget_is_refused_naming_both() -> None:
    with pytest.raises(InputError, match=r"recovered at 1 false alarms/day.*ran at 0\.1/day"):
        efficiency_per_day(_table(1.0), DAYS, source="rec.csv", false_alarms_per_day=0.1)


def test_a_table_at_the_same_budget_or_without_one_gives_the_same_curve() -> None:
    same = efficiency_per_day(_table(0.1), DAYS, false_alarms_per_day=0.1)[DAYS[0]]
    unstated = efficiency_per_day(_table(None), DAYS, false_alarms_per_day=0.1)[DAYS[0]]
    assert same == unstated
    assert same.dH50_Nms == pytest.approx(0.01, rel=0.1)


@pytest.mark.parametrize("bad", ["x", "", "-1"])
def test_a_stated_budget_that_is_not_a_positive_rate_is_refused_naming_its_line(bad: str) -> None:
    table = _table(0.1).astype({"false_alarms_per_day": object})
    table.loc[5, "false_alarms_per_day"] = bad
    with pytest.raises(InputError, match=r"rec\.csv:7: .*false_alarms_per_day.*not a positive rate"):
        efficiency_per_day(table, DAYS, source="rec.csv", false_alarms_per_day=0.1)  # data row 6: line 7
