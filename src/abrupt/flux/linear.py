"""Exactly unbiased flux scales when β is known: the linear estimator with fixed weights.

With β known the expected count of every cell (spacecraft-day, direction class, |ΔH| bin) is linear in the
scales, μ_i = Σ_p s_p a_pi + b_i. For any weights w_i fixed in advance,

    s̃ = J⁻¹ (Σ_events w_e − Σ_i w_i b_i),   J = Σ_i w_i a_iᵀ,

has E s̃ = J⁻¹ Σ_i w_i (μ_i − b_i) = s exactly (E n_i = μ_i), whatever the counts. The weights are the
score's at a reference model θ₀, w_i = a_i / μ_i(θ₀) (θ₀: the published fluxes, s = 1), so at θ₀ s̃ has the
maximum-likelihood estimate's first-order variance. The maximum-likelihood estimate is the same
equation with the weights taken at the estimate itself; that data dependence is what gives it a bias
beyond first order with few detections per population (several per cent on the acceptance fleets:
docs/flux-inference.md). Scales held fixed join the background. Unbiased also means it can go below 0.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError
from abrupt.flux.exposure import DAYS_PER_YEAR
from abrupt.flux.firth import SCALES
from abrupt.flux.forward import DIRECTION_CLASSES
from abrupt.flux.inference import Likelihood


def _cells(lik: Likelihood, beta: float) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Signal at unit scales (P, N), false alarms (N,) and multiplicity (N,) of the distinct day cells."""
    d = lik.data.days
    if not d:
        raise ConfigError("these flux data carry no per-day exposure; build them with prepare()", key="data")
    keys = np.column_stack([d["group"], d["directional"], d["curve"], d["f"], d["fa"]])
    uniq, mult = np.unique(keys, axis=0, return_counts=True)
    n_cls = len(DIRECTION_CLASSES)
    sig: list[NDArray[np.float64]] = []
    bg: list[NDArray[np.float64]] = []
    weight: list[NDArray[np.float64]] = []
    rates = [tpl.bin_rates(beta) for tpl in lik.data.templates]  # (P, C, K) per template group
    for (g, directional, u, f, fa), m in zip(uniq, mult, strict=True):
        r = rates[int(g)]
        eff = f * d["efficiency"][int(u)] / DAYS_PER_YEAR
        share = fa * d["share"][int(u)]
        if directional:
            sig.append((r * eff[None, None, :]).reshape(r.shape[0], -1))
            bg.append(np.tile(share / n_cls, n_cls))
        else:
            sig.append(r.sum(axis=1) * eff[None, :])
            bg.append(share)
        weight.append(np.full(bg[-1].size, float(m)))
    return np.concatenate(sig, axis=1), np.concatenate(bg), np.concatenate(weight)


def linear_estimates(
    lik: Likelihood, fixed: Mapping[str, float], reference: tuple[float, float] = (1.0, 1.0)
) -> dict[str, float]:
    """The fixed-weight linear estimate of the free scales at the one β of ``lik`` (β known).

    Args:
        lik: a likelihood on a single β (``Likelihood(data, np.array([beta]))``); its event weights count.
        fixed: scales held fixed (``debris_scale`` and/or ``meteoroid_scale``), part of the background.
        reference: the scales θ₀ at which the weights are taken (the published models: 1, 1).
    """
    if lik.beta_grid.size != 1:
        raise ConfigError("the linear estimate needs beta known: a likelihood on one beta", key="beta")
    beta = float(lik.beta_grid[0])
    free = [p for p, name in enumerate(SCALES) if name not in fixed]
    known = np.array([float(fixed.get(name, 0.0)) for name in SCALES])
    out = {name: float(known[p]) for p, name in enumerate(SCALES)} | {"beta": beta}
    if not free:
        return out
    s0 = np.array([known[p] if p not in free else reference[p] for p in range(len(SCALES))])
    sig, bg, mult = _cells(lik, beta)
    b_known = bg + known @ sig  # the fixed scales' signal is background for the free ones
    mu0 = s0 @ sig + bg
    use = mu0 > 0
    w = np.where(use, sig[free] / np.where(use, mu0, 1.0), 0.0) * mult  # (F, N), times the day multiplicity
    info = w @ sig[free].T
    a_ev = lik.a[0]  # (E, P) per event at unit scales
    mu0_ev = a_ev @ s0 + lik.bg_events
    score = (lik.weights[:, None] * a_ev[:, free] / np.maximum(mu0_ev, 1e-300)[:, None]).sum(axis=0)
    est = np.linalg.solve(info, score - w @ b_known)
    for i, p in enumerate(free):
        out[SCALES[p]] = float(est[i])
    return out
