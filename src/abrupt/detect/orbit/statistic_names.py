"""The orbit statistics that raise events, by name, each with its summary (Bennett 2022, ch. 3).

Apart from :mod:`abrupt.detect.orbit.detectors` (which needs numba and the filters) so that the
command line can offer the names (``--statistic``) without importing the detectors.
"""

from __future__ import annotations

#: The statistics that raise events, each the registered detector ``orbit.<statistic>``, with its summary.
STATISTIC_SUMMARIES: dict[str, str] = {
    "glr": "sliding GLR of a velocity jump in the forward filter's innovations (default)",
    "accel_smoothed": "smoothed unmodelled acceleration (Bennett 2022 TS3)",
    "mcr_w": "McReynolds consistency of the acceleration states (Bennett 2022 TS4)",
    "mcr_scalar": "scalar McReynolds consistency (Bennett 2022 TS4)",
    "mahalanobis_v": "velocity Mahalanobis distance (Bennett 2022 TS2)",
    "dv_fb": "forward-backward velocity difference (Bennett 2022 TS1)",
    "d_sma": "change of semi-major axis (Bennett 2022 TS6)",
    "d_ecc": "change of eccentricity vector (Bennett 2022 TS6)",
    "d_hdir": "change of angular-momentum direction (Bennett 2022 TS6)",
}
