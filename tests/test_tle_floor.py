"""Recall above the stated floor: an operator burn counts as above when its in-track or cross-track
|ΔV| reaches the smallest detectable ΔV the run states for its year; a burn without a ΔV in the
file counts; a burn in a year the history does not cover does not."""

from __future__ import annotations

import numpy as np
import pandas as pd

from abrupt.pipelines.tle import burns_above_floor

BY_YEAR = [
    {"year": 2002, "min_detectable_dv_t_mps": 0.01, "min_detectable_dv_n_mps": 1.0},
    {"year": 2003, "min_detectable_dv_t_mps": 0.02, "min_detectable_dv_n_mps": 2.0},
]


def test_burns_are_above_the_floor_of_their_own_year() -> None:
    truth = pd.DataFrame(
        {
            "time_utc": [
                "2002-03-01",
                "2002-04-01",
                "2003-03-01",
                "2003-04-01",
                "2003-05-01",
                "2003-06-01",
                "2009-01-01",
            ],
            "dv_t_mps": [0.015, 0.005, 0.015, -0.03, 0.0, np.nan, 1.0],
            "dv_n_mps": [0.0, 0.0, 0.0, 0.0, 2.5, np.nan, 0.0],
        }
    )
    # 2002: 1.5 cm/s over its 1 cm/s floor, 0.5 cm/s under; 2003: 1.5 cm/s under its 2 cm/s floor,
    # -3 cm/s over, a 2.5 m/s cross-track burn over the 2 m/s one, no ΔV counted; 2009 not covered
    assert burns_above_floor(truth, BY_YEAR).tolist() == [True, False, False, True, True, True, False]
    assert not burns_above_floor(truth, []).any()


def test_opposite_cross_track_burns_are_judged_by_their_summed_magnitude() -> None:
    """A line of two opposite 1.25 m/s cross-track burns nets to zero in its components but turns the
    plane by 2.5 m/s: above the 2 m/s floor of 2003; one of 1.5 m/s in all is below it."""
    truth = pd.DataFrame(
        {
            "time_utc": ["2003-03-01", "2003-04-01"],
            "dv_t_mps": [0.0, 0.0],
            "dv_n_mps": [0.0, 0.0],
            "dv_n_abs_mps": [2.5, 1.5],
        }
    )
    assert burns_above_floor(truth, BY_YEAR).tolist() == [True, False]
    assert not burns_above_floor(truth.drop(columns="dv_n_abs_mps"), BY_YEAR).any()
