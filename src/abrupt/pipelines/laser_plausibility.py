"""Laser ranging inside its physical envelope: ranges against the a-priori orbit, fitted parameters bounded.

Two checks frame :func:`abrupt.pipelines.laser_ranging.run_laser_ranging_files`:

- **before the fit** (:func:`check_ranges_against_apriori`): every station's measured one-way ranges
  against the geometric ranges from its site to the a-priori ephemeris at the bounce epochs. An ILRS
  prediction (CPF) is good to metres or, for a stale one, kilometres along-track: a few per mille of a
  range of thousands of km. A station whose median ranges differ from the a-priori ones by more than
  :data:`MAX_APRIORI_RANGE_RATIO` (1 %) has ranges in a wrong unit or scale (×0.001, ×6), or the a-priori
  is another satellite's: refused, naming the station and the ratio;
- **after the fit** (:func:`fit_bound_violations`): the parameters the fit estimates must stay physical.
  A range bias is a station's calibration error or the target's centre-of-mass offset: centimetres to
  decimetres, at most :data:`MAX_RANGE_BIAS_M`. A force scale multiplies an a-priori coefficient whose
  physics bounds it: the radiation-pressure coefficient C_R of a body lies between 1 (absorbing) and 2
  (specular), so with A/m known to ±25 % the scale of the a-priori C_R·A/m lies in
  :data:`SRP_SCALE_BOUNDS`; drag follows an atmosphere model good to a factor of 3 (:data:`DRAG_SCALE_BOUNDS`).
  A fit that needs more absorbs a residual its model cannot explain, and a post-fit range RMS above
  :data:`MAX_POSTFIT_RMS_M` is a residual it could not absorb; its detections are then reported as such
  (kind ``unknown``, the violations named), not as maneuvers.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from abrupt.errors import InputError
from abrupt.model.propulsion import unmodelled_acceleration_mps2
from abrupt.model.range_reduction import StationSite
from abrupt.series.ephemeris import Ephemeris

MAX_APRIORI_RANGE_RATIO = 0.01  # median |measured / a-priori range − 1| of a station above this: refused
MIN_RANGES_CHECKED = 3  # fewer ranges of a station inside the ephemeris: not checked
MAX_RANGE_BIAS_M = 1.0  # [m] largest physical range bias (station calibration + centre-of-mass offset)
MAX_POSTFIT_RMS_M = 1.0  # [m] normal points are mm to cm: a metre of post-fit RMS is not noise
SRP_SCALE_BOUNDS = (0.66, 2.2)  # C_R in [1, 2] against an a-priori 1.13, A/m within ±25 %
DRAG_SCALE_BOUNDS = (0.33, 3.0)  # an atmosphere model good to a factor of 3
SCALE_BOUNDS = {"srp_scale": SRP_SCALE_BOUNDS, "drag_scale": DRAG_SCALE_BOUNDS}


def apriori_ranges_m(measurements: pd.DataFrame, sites: Mapping[str, StationSite], ephemeris: Ephemeris) -> np.ndarray:
    """Geometric one-way ranges (m) from each measurement's site to the a-priori ephemeris (Earth-fixed,
    cubic in time) at its bounce epoch (receive time less half the time of flight); NaN outside the
    ephemeris' span."""
    itrf = ephemeris.to_frame("ITRF")
    epoch = itrf.times_utc[0]
    t_eph = (itrf.times_utc - epoch) / np.timedelta64(1, "s")
    times = np.asarray(measurements["time_utc"], dtype="datetime64[ns]")
    t = (times - epoch) / np.timedelta64(1, "s")
    if "time_of_flight_s" in measurements:
        t = t - 0.5 * np.nan_to_num(measurements["time_of_flight_s"].to_numpy(dtype=float))
    out = np.full(len(measurements), np.nan)
    if t_eph.size < 4:
        return out
    spline = CubicSpline(t_eph, itrf.position_m, axis=0)
    inside = (t >= t_eph[0]) & (t <= t_eph[-1])
    sat = spline(t[inside])
    site = np.array([sites[str(s)].position_ecef_m for s in measurements["station"].to_numpy()[inside]], dtype=float)
    out[inside] = np.linalg.norm(sat - site.reshape(-1, 3), axis=1)
    return out


def check_ranges_against_apriori(
    measurements: pd.DataFrame, sites: Mapping[str, StationSite], ephemeris: Ephemeris, *, file: str
) -> dict[str, float]:
    """Refuse a station whose ranges are not those of the a-priori orbit (module docstring); returns each
    checked station's median ratio of measured to a-priori range."""
    expected = apriori_ranges_m(measurements, sites, ephemeris)
    measured = measurements["range_m"].to_numpy(dtype=float)
    ratios: dict[str, float] = {}
    stations = measurements["station"].astype(str).to_numpy()
    for name in sorted(set(stations)):
        sel = (stations == name) & np.isfinite(expected) & np.isfinite(measured) & (expected > 0)
        if int(sel.sum()) < MIN_RANGES_CHECKED:
            continue
        ratio = float(np.median(measured[sel] / expected[sel]))
        ratios[name] = ratio
        if not abs(ratio - 1.0) <= MAX_APRIORI_RANGE_RATIO:
            raise InputError(
                f"station {name}: its ranges are {ratio:.4g} times those of the a-priori orbit {ephemeris.source} "
                f"(median of {int(sel.sum())}; within {100 * MAX_APRIORI_RANGE_RATIO:g} % expected): ranges in a "
                "wrong unit or scale, or an a-priori of another satellite",
                file=file,
            )
    return ratios


def fit_bound_violations(
    range_bias_m: Mapping[str, float],
    scale_factors: Mapping[str, float],
    residual_rms_m: Mapping[str, float] | None = None,
) -> list[str]:
    """The fitted parameters outside their physical bounds (module docstring), and stations whose post-fit
    range RMS exceeds :data:`MAX_POSTFIT_RMS_M` (residuals the fit cannot absorb), one phrase each."""
    out = [
        f"post-fit range RMS {rms:.3g} m at station {name} (≤ {MAX_POSTFIT_RMS_M:g} m)"
        for name, rms in sorted((residual_rms_m or {}).items())
        if not rms <= MAX_POSTFIT_RMS_M
    ]
    out += [
        f"range bias {1e3 * b:.0f} mm at station {name} (|bias| ≤ {1e3 * MAX_RANGE_BIAS_M:.0f} mm)"
        for name, b in sorted(range_bias_m.items())
        if not abs(b) <= MAX_RANGE_BIAS_M
    ]
    for name, value in sorted(scale_factors.items()):
        lo, hi = SCALE_BOUNDS.get(name, (0.0, np.inf))
        if not lo <= value <= hi:
            out.append(f"{name} {value:.3g} (physical {lo:g}-{hi:g})")
    return out


def passive_detections(
    events: pd.DataFrame, satellite: str, area_to_mass_m2_kg: float, longest_gap_s: float
) -> tuple[pd.DataFrame, list[str]]:
    """Events of a satellite without propulsion: the ΔV its model explains is the unmodelled
    non-gravitational acceleration (:func:`abrupt.model.propulsion.unmodelled_acceleration_mps2`) acting
    over the longest gap between ranges, where the GLRT places impulses. Detections within it are dropped
    as explained; those above it are kept as kind ``unknown`` and named as bad input or a force the model
    lacks, never burns. Returns the events and the warnings."""
    limit = unmodelled_acceleration_mps2(area_to_mass_m2_kg) * max(longest_gap_s, 0.0)
    notes = [
        f"{satellite} has no propulsion: its model explains |ΔV| up to {1e3 * limit:.3g} mm/s "
        f"(radiation pressure and albedo over the longest gap between ranges, {longest_gap_s / 3600:.3g} h)"
    ]
    if not len(events):
        return events, notes
    explained = events["dv_mps"].to_numpy(dtype=float) <= limit
    out = events.loc[~explained].copy()
    if explained.any():
        notes.append(f"{int(explained.sum())} detection(s) within the ΔV the model explains: not events")
    if len(out):
        out["kind"] = "unknown"
        notes.append(
            f"{len(out)} detection(s) of |ΔV| up to {1e3 * float(out['dv_mps'].max()):.4g} mm/s exceed it: not burns "
            "(no propulsion) but bad input or a force the model lacks; kept as kind unknown"
        )
    return out.reset_index(drop=True), notes
