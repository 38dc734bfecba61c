"""Momentum enhancement factor β (Bennett 2022 §5.3.3.5; spec §6.7).

ΔP = β m v (Eq. 5.1). Models, with the relative speed v in km/s inside the fits:

* ``const1``, ``const2``, ``const3`` (or ``const:<value>``): static β; NESC bounded with 1 and 3.
* ``nysmith_denardo``: β = 1 + 0.144 (v - 0.55)² / v (Eq. 5.12; lower McDonnell fit).
* ``rembor``: β = 1 + 0.3 (v - 2) (Eq. 5.13; higher McDonnell fit).
* ``rembor_array``: Rembor on the bus, β = 0.5 for any strike on a solar array (model D).

The fits are floored at β = 1 (a particle that stops in the target transfers at least its own
momentum); this matters only below 2 km/s (Rembor), which debris relative speeds rarely reach.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from abrupt.errors import ConfigError

MEF_MODELS = ("const1", "const2", "const3", "nysmith_denardo", "rembor", "rembor_array")
ARRAY_MEF = 0.5  # [-] β for solar-array strikes in model D (Ryan 2021, via Bennett 2022)


def nysmith_denardo(speed_mps: ArrayLike) -> NDArray[np.float64]:
    """Nysmith-Denardo β (Bennett 2022 Eq. 5.12), speed in m/s."""
    v = np.asarray(speed_mps, dtype=np.float64) / 1e3
    return np.asarray(np.maximum(1.0 + 0.144 * (v - 0.55) ** 2 / v, 1.0), dtype=np.float64)


def rembor(speed_mps: ArrayLike) -> NDArray[np.float64]:
    """Rembor β (Bennett 2022 Eq. 5.13), speed in m/s."""
    v = np.asarray(speed_mps, dtype=np.float64) / 1e3
    return np.asarray(np.maximum(1.0 + 0.3 * (v - 2.0), 1.0), dtype=np.float64)


def momentum_enhancement(model: str, speed_mps: ArrayLike, on_array: ArrayLike | None = None) -> NDArray[np.float64]:
    """β per strike for a named model; ``on_array`` flags solar-array strikes (model ``rembor_array``)."""
    v = np.asarray(speed_mps, dtype=np.float64)
    if np.any(~np.isfinite(v)) or np.any(v <= 0):
        raise ConfigError("relative speeds must be positive and finite", key="speed_mps")
    if model.startswith("const"):
        text = model.split(":", 1)[1] if ":" in model else model[len("const") :]
        try:
            value = float(text)
        except ValueError:
            raise ConfigError(f"cannot read a constant MEF from {model!r}", key="mef") from None
        if not value > 0:
            raise ConfigError("constant MEF must be positive", key="mef")
        return np.full(v.shape, value)
    if model == "nysmith_denardo":
        return nysmith_denardo(v)
    if model == "rembor":
        return rembor(v)
    if model == "rembor_array":
        beta = rembor(v)
        if on_array is not None:
            beta = np.where(np.asarray(on_array, dtype=bool), ARRAY_MEF, beta).astype(np.float64)
        return beta
    raise ConfigError(f"unknown MEF model {model!r}; choose one of {list(MEF_MODELS)} or const:<value>", key="mef")
