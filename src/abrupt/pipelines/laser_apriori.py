"""A-priori orbit of a laser-ranging run from a TLE or OMM: SGP4, then a short-arc fit to the ranges.

Everyone has element sets of their satellite; few have a precise orbit. An element set propagated by
SGP4 (:func:`abrupt.model.teme.sgp4_state_gcrf`: TEME to GCRF) is hundreds of metres to kilometres
off, too far for the detector's fit of a week of ranges (Gauss-Newton converges from tens of metres
over a day; :mod:`abrupt.detect.tracking.laser`). So the a-priori state is first fitted to the ranges
themselves over a short arc that grows (:data:`SHORT_ARC_HOURS`: 6, 12, 24, 48 h, the ranges there
are): the state only (no station biases, no force scales: a few passes cannot separate them), each
span started from the last one's state, then the state is the a-priori of the detection. A span whose
fit does not reach the ranges' own precision (:data:`MAX_SHORT_ARC_RMS_M`) holds a maneuver (or did
not converge): the growth stops at the span before it; when even the first span does not fit, the
run is refused with the figure, never passed on.

The element set nearest in time to the arc is used; one more than :data:`MAX_ELEMENT_AGE_DAYS` from
it is refused (SGP4 errors grow by kilometres a day).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError
from abrupt.model.orbit import ForceContext
from abrupt.model.orbit.batch_fit import BatchFitConfig, fit_orbit
from abrupt.model.range_reduction import RangeModel, StationSite
from abrupt.model.stations import Station
from abrupt.model.teme import sgp4_state_gcrf
from abrupt.model.tracking_measurements import as_datetime64_ns
from abrupt.readers.omm import read_element_histories
from abrupt.readers.tle import ElementHistory, is_tle_text, read_element_bytes
from abrupt.series.tracking import LaserRangingSeries
from abrupt.types import FloatArray

SHORT_ARC_HOURS = (6.0, 12.0, 24.0, 48.0)
"""Spans of the short-arc fit [h]: each fitted from the previous one's state."""
MIN_SHORT_ARC_RANGES = 20
"""A span with fewer ranges is skipped (its fit would be underdetermined)."""
MAX_SHORT_ARC_RMS_M = 1.0
"""Post-fit range RMS [m] above which the short-arc fit is refused (laser normal points: millimetres;
a fit that stops at metres did not converge, or the element set is of another object)."""
MAX_ELEMENT_AGE_DAYS = 30.0
"""An arc further than this [days] from every element set has no a-priori from the elements."""


def is_element_file(path: str | Path) -> bool:
    """Whether a file holds TLE/3LE or OMM (KVN, XML, JSON) element sets rather than an ephemeris, from its
    first bytes."""
    head = read_element_bytes(Path(path))[:4000].decode("utf-8", errors="replace").lstrip("\ufeff\r\n\t ")
    lowered = head.lower()
    if is_tle_text(head) or head.startswith("CCSDS_OMM_VERS"):
        return True
    if head.startswith("<"):  # XML: an OMM, or an OEM (an ephemeris)
        return "<omm" in lowered or ":omm" in lowered
    return head.startswith(("[", "{")) and "mean_motion" in lowered  # OMM as JSON (Space-Track, CelesTrak)


@dataclass
class ElementApriori:
    """One satellite's element sets, as the a-priori of a laser-ranging run (module docstring)."""

    history: ElementHistory
    source: str
    fits: list[dict[str, object]] = field(default_factory=list)

    @classmethod
    def read(cls, path: str | Path) -> ElementApriori:
        """The element sets of a TLE/3LE or OMM file holding one satellite (several: an error)."""
        histories = [h for h in read_element_histories(path) if len(h.elements)]
        if not histories:
            raise InputError("no element sets to take an a-priori orbit from", file=path)
        if len(histories) > 1:
            ids = ", ".join(str(h.norad_id) for h in histories[:5])
            raise InputError(f"element sets of {len(histories)} satellites ({ids}); give a file of one", file=path)
        return cls(histories[0], str(path))

    def nearest(self, time_utc: np.datetime64) -> tuple[int, float]:
        """Index of the element set nearest in time, and its distance [days]."""
        epochs = np.asarray(self.history.elements["epoch_utc"], dtype="datetime64[ns]")
        gaps = np.abs((epochs - as_datetime64_ns(time_utc)) / np.timedelta64(1, "D")).astype(float)
        k = int(np.argmin(gaps))
        return k, float(gaps[k])

    def state_gcrf(self, time_utc: np.datetime64) -> FloatArray | None:
        """SGP4 state (GCRF, m and m/s) at ``time_utc`` from the nearest element set; None when every set
        is more than :data:`MAX_ELEMENT_AGE_DAYS` away."""
        k, gap = self.nearest(time_utc)
        if gap > MAX_ELEMENT_AGE_DAYS:
            return None
        return sgp4_state_gcrf(self.history.satrecs[k], time_utc)


def short_arc_fit(
    measurements: pd.DataFrame,
    sites: dict[str, StationSite],
    stations: dict[str, Station],
    x0_sgp4: FloatArray,
    epoch_utc: np.datetime64,
    fit_config: BatchFitConfig,
    *,
    range_model: RangeModel | None = None,
    source: str = "<elements>",
) -> tuple[FloatArray, dict[str, object]]:
    """The GCRF state at ``epoch_utc`` fitted to the ranges of the first hours from ``x0_sgp4`` (module
    docstring), and a summary: spans fitted, post-fit RMS [m], the SGP4 state's position and velocity
    offsets from the fitted one [m, m/s]. A fit above :data:`MAX_SHORT_ARC_RMS_M` is an InputError."""
    epoch = as_datetime64_ns(epoch_utc)
    t_rel = (np.asarray(measurements["time_utc"], dtype="datetime64[ns]") - epoch) / np.timedelta64(1, "s")
    model_f = fit_config.force.model if isinstance(fit_config.force, ForceContext) else fit_config.force
    cfg = replace(fit_config, estimate_range_bias=False, estimate_time_bias=False, estimate_scales=())
    x = np.asarray(x0_sgp4, float).copy()
    spans: list[float] = []
    rms_m, worst = math.inf, (0.0, math.inf)
    n_fitted = 0
    for hours in SHORT_ARC_HOURS:
        sel = (t_rel >= 0.0) & (t_rel <= hours * 3600.0)
        if int(sel.sum()) < MIN_SHORT_ARC_RANGES or int(sel.sum()) == n_fitted:  # too few, or no new range
            continue
        n_fitted = int(sel.sum())
        part = measurements.loc[sel].reset_index(drop=True)
        t_end = float(t_rel[sel].max())
        ctx = ForceContext.build(model_f, epoch, -86400.0, t_end + 86400.0)
        series = LaserRangingSeries(
            part, sites, stations, x, epoch, replace(cfg, force=ctx), range_model or RangeModel()
        )
        data = series.reduced(x, {})
        fit = fit_orbit(data, x, config=series.fit_config)
        resid_m = fit.residuals_white * data.sigma[fit.row_index, fit.row_component]
        span_rms_m = float(np.sqrt(np.mean(resid_m[fit.used] ** 2)))
        if not span_rms_m <= MAX_SHORT_ARC_RMS_M:
            # a maneuver inside the longer span (or no convergence): keep the last span that fitted
            worst = (hours, span_rms_m)
            break
        x, rms_m = np.asarray(fit.x0, float), span_rms_m
        spans.append(hours)
    if n_fitted == 0:
        raise InputError(
            f"fewer than {MIN_SHORT_ARC_RANGES} ranges in the first {SHORT_ARC_HOURS[-1]:g} h after {epoch}: "
            "too few to fit the a-priori orbit from the elements",
            file=source,
        )
    if not spans:
        raise InputError(
            f"the orbit fitted to the ranges from the element set leaves {worst[1]:.3g} m RMS over "
            f"{worst[0]:g} h (at most {MAX_SHORT_ARC_RMS_M:g} m): are the elements of this satellite and "
            "near the ranges' dates?",
            file=source,
        )
    offset = x - np.asarray(x0_sgp4, float)
    return x, {
        "epoch_utc": str(epoch),
        "short_arc_hours": spans,
        "short_arc_rms_m": round(rms_m, 4),
        "sgp4_position_offset_m": round(float(np.linalg.norm(offset[:3])), 1),
        "sgp4_velocity_offset_mps": round(float(np.linalg.norm(offset[3:])), 4),
    }
