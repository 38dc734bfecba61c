"""The double-heap running median against pandas' skip-list rolling median (another library's numbers)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from abrupt.clean.rolling_median import running_median


@pytest.mark.parametrize("seed", range(6))
def test_running_median_equals_pandas_rolling_median_with_gaps_ties_and_both_window_parities(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, window = int(rng.integers(50, 3000)), int(rng.integers(1, 400))
    min_periods = int(rng.integers(0, window + 1))
    x = rng.standard_normal((n, 3))
    x[:, 1] = np.round(x[:, 1], 1)  # ties
    x[rng.random(n) < 0.2, 0] = np.nan  # scattered gaps
    x[10:40, 2] = np.nan  # a long gap
    x[5, 0] = np.inf  # counted as missing, as pandas does
    ref = pd.DataFrame(x).rolling(window, center=True, min_periods=min_periods).median().to_numpy()
    assert np.array_equal(running_median(x, window, min_periods), ref, equal_nan=True)


def test_running_median_of_a_ramp_is_the_ramp_inside_and_clipped_windows_at_the_ends() -> None:
    x = np.arange(20.0)
    m = running_median(x, 5, 1)
    assert np.array_equal(m[2:-2], x[2:-2])  # a full odd window of a line: its middle sample
    assert m[0] == 1.0 and m[1] == 1.5  # windows [0, 1, 2] and [0 .. 3]
    assert np.isnan(running_median(np.full(4, np.nan), 3, 1)).all()
    with pytest.raises(ValueError, match="window"):
        running_median(x, 0, 1)
