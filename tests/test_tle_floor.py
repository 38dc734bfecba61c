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
