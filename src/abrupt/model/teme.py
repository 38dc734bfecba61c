"""SGP4's frame (TEME) to GCRF, and the GCRF state of an element set at a time.

SGP4 (:mod:`sgp4`) gives positions and velocities in the True Equator, Mean Equinox frame of date
(TEME). Vallado et al. 2006 ("Revisiting Spacetrack Report #3", AIAA 2006-6753, Eqs. 1-3): TEME turns
into the true-of-date frame by the equation of the equinoxes (IAU 1994, ``erfa.eqeq94``), the
true-of-date frame into mean J2000 by the transposed IAU 1976/1980 precession-nutation matrix
(``erfa.pnm80``), and mean J2000 into GCRF by the transposed frame bias (``erfa.bp00``, 23 mas):

    r_TOD = R3(−Eq_eq) r_TEME,   r_J2000 = [NP]^T r_TOD,   r_GCRF = [B]^T r_J2000

R3 is a frame rotation about z. TEME turns with precession and nutation only (micro-radians per day),
so velocities take the same matrix. Times: UTC to TT with astropy's bundled leap-second table (no
download). An element set's own error (hundreds of metres to kilometres) is far above what this
leaves out (polar motion does not enter; the IAU 1976/1980 model differs from IAU 2006/2000A by
milliarcseconds, a few centimetres at LEO, a metre at 20,000 km).
"""

from __future__ import annotations

import erfa
import numpy as np
from astropy.time import Time
from numpy.typing import NDArray
from sgp4.api import Satrec

from abrupt.model.timescales import offline_astropy
from abrupt.model.tracking_measurements import as_datetime64_ns
from abrupt.types import FloatArray


def _rot_z(angle: float) -> FloatArray:
    """Frame rotation R3(angle) about z (rad)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def teme_to_gcrf_matrix(time_utc: np.datetime64) -> FloatArray:
    """The 3×3 matrix M with r_GCRF = M r_TEME at ``time_utc`` (module docstring)."""
    offline_astropy()
    tt = Time(np.asarray([time_utc], dtype="datetime64[ns]"), scale="utc", format="datetime64").tt
    tt1, tt2 = float(tt.jd1[0]), float(tt.jd2[0])
    teme_to_tod = _rot_z(-float(erfa.eqeq94(tt1, tt2)))
    np_matrix = np.asarray(erfa.pnm80(tt1, tt2), dtype=np.float64)  # r_TOD = [NP] r_J2000
    bias = np.asarray(erfa.bp00(tt1, tt2)[0], dtype=np.float64)  # r_J2000 = [B] r_GCRF
    return np.asarray(bias.T @ np_matrix.T @ teme_to_tod, dtype=np.float64)


def sgp4_state_gcrf(satrec: Satrec, time_utc: np.datetime64) -> FloatArray:
    """GCRF position and velocity (m, m/s) of an element set propagated by SGP4 to ``time_utc``.

    SGP4's time argument is the UTC Julian date (as element-set epochs are UTC); an element set SGP4
    cannot propagate to that time (decayed, error code) is a :class:`ValueError`.
    """
    t = as_datetime64_ns(time_utc)
    days = (t - np.datetime64("1949-12-31T00:00:00", "ns")) / np.timedelta64(1, "D")
    jd = 2433281.5 + float(days)  # JD of 1949-12-31 00:00 UTC
    err, r_km, v_kms = satrec.sgp4(np.floor(jd), jd - np.floor(jd))
    if err != 0:
        raise ValueError(f"SGP4 cannot propagate the element set to {t} (error code {err})")
    m = teme_to_gcrf_matrix(t)
    return np.concatenate([m @ (1e3 * np.asarray(r_km)), m @ (1e3 * np.asarray(v_kms))])


def sgp4_states_gcrf(satrec: Satrec, times_utc: NDArray[np.datetime64]) -> FloatArray:
    """:func:`sgp4_state_gcrf` at each of ``times_utc``, shape (n, 6)."""
    return np.array([sgp4_state_gcrf(satrec, t) for t in np.asarray(times_utc, dtype="datetime64[ns]")])
