"""Spacecraft-days of the flux inference: their template keys and bin efficiencies, and one exposure per
spacecraft-day when several detectors analysed the same day.

A strike on a spacecraft-day is one event of one Poisson process, whichever detectors look for it. When two
detectors analysed the same day (say the attitude and the orbit detector), the exact expectation of the
*merged* detections would be the rate times the probability that at least one of them found the strike,

    μ(x) = rate(x) · P(t ∈ A₁ and detector 1 finds it, or t ∈ A₂ and detector 2 finds it),

which needs three things the catalog does not hold: the analysed intervals A₁, A₂ (an exposure row stores
the analysed *fraction* only, so their overlap is anywhere from f₁ + f₂ − 1 to min(f₁, f₂)), the joint
detection probability of one strike by both (strongly correlated through the same |ΔH|, not measured by
the per-detector injections), and an association of the two detectors' events of the same strike (the
catalog joins detections of one detector only). "The union of analysed time with the better efficiency per
bin" is not a bound either way: two detectors with disjoint analysed hours, one blind at some |ΔH|, would
be credited with the other's efficiency over both. Counting both detectors' events against the sum of their
exposures keeps the mean right but counts a strike seen twice as two independent events (intervals too
narrow by up to √2).

The rule used instead is exact with what is stored: **per spacecraft-day, the exposure row of the detector
expected to see the most strikes is kept** (its f ∫ ε dG at the reference model: unit flux scales, β = 1,
summed over populations and bins), **with that detector's events of the day; the other rows and the other
detectors' events of that day are set aside and counted**. The choice depends on the exposure only, never
on the events, so the kept data are an unbiased Poisson sample with a known exposure; the price is the
information of the set-aside detector on shared days.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.errors import InputError
from abrupt.flux.exposure import logistic_efficiency
from abrupt.flux.forward import OrbitCase, Template


@dataclass(frozen=True)
class Selection:
    """Exposure rows and events kept, with what was set aside."""

    exposure: pd.DataFrame
    events: pd.DataFrame
    rows_set_aside: int
    events_set_aside: int


def day_keys(spacecraft: pd.Series, day: pd.Series) -> NDArray[np.object_]:
    return np.asarray(spacecraft.astype(str).to_numpy(dtype=object) + "|" + day.astype(str).to_numpy(dtype=object))


def one_exposure_per_day(
    exposure: pd.DataFrame,
    events: pd.DataFrame,
    event_days: pd.Series,
    expected_signal: Callable[[pd.DataFrame], NDArray[np.float64]],
) -> Selection:
    """Keep one exposure row per spacecraft-day (see the module docstring) and the events that go with it.

    Args:
        exposure: exposure frame (``exposure_frame``), possibly with several rows for a spacecraft-day.
        events: strike events, with ``spacecraft`` and ``detector``.
        event_days: the UTC day (YYYY-MM-DD) of each event, aligned with ``events``.
        expected_signal: expected detections at the reference model of each row of a frame of rows.
    """
    keys = day_keys(exposure["spacecraft"], exposure["day"])
    shared = pd.Index(keys).duplicated(keep=False)
    if not shared.any():
        return Selection(exposure, events, 0, 0)
    rows = exposure[shared]
    for key, group in rows.groupby(keys[shared], sort=False):
        names = group["detector"].astype(str)
        if (names == "").any() or names.duplicated().any():
            raise InputError(
                f"exposure has {len(group)} rows for spacecraft-day {str(key).replace('|', ' ')} (detectors "
                f"{', '.join(sorted(n or '(none)' for n in names))}); rows sharing a day need distinct detector "
                "names, to match each detector's events (keep one configuration per detector and day)"
            )
    signal = np.asarray(expected_signal(rows), dtype=np.float64)
    order = pd.DataFrame(
        {"key": keys[shared], "signal": -signal, "detector": rows["detector"].astype(str).to_numpy()},
        index=rows.index,
    ).sort_values(["key", "signal", "detector"])
    winners = order.drop_duplicates("key")
    dropped_rows = order.index.difference(winners.index)
    kept_detector = dict(zip(winners["key"], winners["detector"], strict=True))
    ev_keys = day_keys(events["spacecraft"], event_days)
    chosen = pd.Series(ev_keys, index=events.index).map(kept_detector)
    off = chosen.notna().to_numpy() & (events["detector"].astype(str).to_numpy() != chosen.fillna("").to_numpy())
    return Selection(
        exposure.drop(index=dropped_rows),
        events[~off],
        int(dropped_rows.size),
        int(off.sum()),
    )


def case_of(row: Mapping[Any, Any]) -> OrbitCase:
    """The template key of an exposure row."""
    epoch = float(row["epoch_year"])
    return OrbitCase(
        str(row["spacecraft_file"]),
        float(row["altitude_km"]),
        float(row["inclination_deg"]),
        2020.0 if not math.isfinite(epoch) else epoch,
    )


def bin_efficiency(
    edges: NDArray[np.float64],
    curves: NDArray[np.float64],
    n_sub: int = 16,
    slopes: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Efficiency over each |ΔH| bin for curves (U, 3) of (x50, slope, plateau), sampled at ``n_sub`` points
    uniform in ln|ΔH| (the open top bin over one bin width), so that steep curves are not sampled at the
    centre only: (U, K), the plain mean; with ``slopes`` (..., K), local power-law slopes α of the strike
    spectrum (dG ∝ x^−α d ln x), the mean weighted by that spectrum within the bin, (U, ..., K)."""
    lo = np.log(edges[:-1])
    upper = np.append(edges[1:-1], edges[-2] * (edges[-2] / edges[-3]))
    hi = np.log(upper)
    t = (np.arange(n_sub) + 0.5) / n_sub
    x = np.exp(lo[:, None] + (hi - lo)[:, None] * t[None, :])  # (K, S)
    eff = logistic_efficiency(
        x[None, :, :], curves[:, 0, None, None], curves[:, 1, None, None], curves[:, 2, None, None]
    )
    if slopes is None:
        return np.asarray(eff.mean(axis=2), dtype=np.float64)
    alpha = np.clip(np.asarray(slopes, dtype=np.float64), -20.0, 20.0)[..., None]  # (..., K, 1)
    w = np.exp(-alpha * (np.log(x) - lo[:, None]))  # (..., K, S), relative to the bin's lower edge
    w = w / w.sum(axis=-1, keepdims=True)
    return np.asarray(np.einsum("uks,...ks->u...k", eff, w), dtype=np.float64)


def case_groups(exposure: pd.DataFrame) -> tuple[list[OrbitCase], NDArray[np.int64]]:
    """The distinct template keys of exposure rows (in order of appearance) and each row's index into them."""
    cols = ["spacecraft_file", "altitude_km", "inclination_deg", "epoch_year"]
    codes = exposure.groupby(cols, sort=False, dropna=False).ngroup().to_numpy()
    keys = [case_of(rec) for rec in exposure.drop_duplicates(cols).to_dict("records")]
    return keys, np.asarray(codes, dtype=np.int64)


def reference_signal(rows: pd.DataFrame, templates: Mapping[OrbitCase, Template]) -> NDArray[np.float64]:
    """Expected detections of each exposure row at unit flux scales and β = 1 (all populations and bins)."""
    out = np.empty(len(rows))
    for i, rec in enumerate(rows.to_dict("records")):
        tpl = templates[case_of(rec)]
        curve = np.array([[rec["dH50_Nms"], rec["efficiency_slope"], rec["efficiency_max"]]], dtype=np.float64)
        eff = bin_efficiency(tpl.config.edges_Nms, curve)[0]
        out[i] = float(rec["analysed_fraction"]) * float(eff @ tpl.bin_rates(1.0).sum(axis=(0, 1)))
    return out
