"""Orbit detectors as :class:`~abrupt.detect.base.Detector` classes: one per statistic, ``orbit.<statistic>``.

One class, :class:`OrbitDetector`, registered once per statistic. All share the same machinery
(:mod:`abrupt.detect.orbit.analysis` and the modules beside it: forward EKF-DMC with the one orbit
model, mirrored backward filter, Fraser-Potter fusion, statistics, thresholds, events; Bennett 2022
ch. 3) and differ in the statistic that raises events:

======================  ==========================================================================
``orbit.glr``           sliding generalised likelihood ratio of a velocity jump (default, real data)
``orbit.accel_smoothed``  smoothed unmodelled acceleration w_S (TS3, Bennett 2022 §3.3.3)
``orbit.mcr_w``         McReynolds consistency of the acceleration states (TS4)
``orbit.mcr_scalar``    scalar McReynolds consistency (TS4, inverse form)
``orbit.mahalanobis_v``  velocity Mahalanobis distance (TS2)
``orbit.dv_fb``         forward-backward velocity difference (TS1)
``orbit.d_sma``, ``orbit.d_ecc``, ``orbit.d_hdir``  change of orbital constants (TS6)
======================  ==========================================================================

Settings (constructor keywords): ``tuning`` ("auto": τ, q and measurement sigmas from the data with
the full force model; "thesis": Table 3.1, two-body), overrides ``tau_s``, ``q_m2_s5``,
``sigma_pos_m``, ``sigma_vel_mps``, ``dynamics`` ("two-body", "j2".."j4", "field"),
``gravity_degree``, ``null`` (an event-free :class:`~abrupt.series.ephemeris.Ephemeris` of the same
satellite for thresholds; default: the arc itself with leave-out), ``confidence_z`` (standard errors
added to a self-calibrated level), ``kind`` and ``nuisance`` (estimate drag and SRP scale factors and
once-per-revolution empirical accelerations as filter states, with NRLMSIS drag tabulated along the
observed orbit; :class:`~abrupt.detect.orbit.ekf.NuisanceConfig`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.detect.orbit.analysis import OrbitAnalysis, OrbitDetectorConfig, analyse, innovation_scale
from abrupt.detect.orbit.boundaries import (
    SHADOW,
    ProductBoundary,
    boundary_mask,
    eclipse_mask,
    product_boundaries,
)
from abrupt.detect.orbit.calibration import calibrate_thresholds, self_calibrate
from abrupt.detect.orbit.discontinuity import split_discontinuities
from abrupt.detect.orbit.ekf import FilterConfig, NuisanceConfig
from abrupt.detect.orbit.events import find_events
from abrupt.detect.orbit.statistic_names import STATISTIC_SUMMARIES
from abrupt.detect.orbit.tuning import auto_tune
from abrupt.errors import InputError
from abrupt.events import config_hash
from abrupt.model.orbit import ForceModel
from abrupt.series.ephemeris import Ephemeris
from abrupt.thresholds import FalseAlarmBudget, Threshold
from abrupt.types import FloatArray

TUNINGS = ("auto", "thesis")
DYNAMICS = {"two-body": 0, "j2": 2, "j3": 3, "j4": 4, "field": -1}
SETTLE_CAP_S = 6 * 3600.0  # [s] longest settling time excluded at each end of an arc
DEFAULT_GRAVITY_DEGREE = 40  # chosen from benchmarks/bench_orbit_forces.py (post-fit residuals, S3A and Jason-1)
#: nominal spacecraft of the nuisance model: area-to-mass 0.01 m²/kg (typical of LEO satellites,
#: 0.005-0.02); the estimated scale factors absorb the actual value
NOMINAL_MASS_KG = 1000.0
NOMINAL_AREA_M2 = 10.0


def nuisance_force_model(gravity_degree: int, third_body: bool, zonal_degree: int = 0) -> ForceModel:
    """The filter's force model when nuisance parameters are estimated: the gravity of the plain filter plus
    NRLMSIS drag (tabulated along the observed orbit) and cannonball SRP with a conical shadow, both for
    the nominal spacecraft (their scale factors are filter states)."""
    return ForceModel(
        zonal_degree=zonal_degree,
        gravity_degree=gravity_degree,
        sun=third_body,
        moon=third_body,
        drag="msis",
        srp=True,
        mass_kg=NOMINAL_MASS_KG,
        drag_area_m2=NOMINAL_AREA_M2,
        srp_area_m2=NOMINAL_AREA_M2,
    )


class ArcTooShortError(InputError):
    """An arc shorter than the filters' settling at both ends: no epoch can be tested. Pipelines turn it into
    a warning and a recorded run that tested nothing, so that a batch over many files does not stop."""


class OrbitDetector(Detector[Ephemeris]):
    """The orbit detector; registered once per statistic (:data:`ORBIT_DETECTORS`), which sets ``name``
    and ``statistic``. The detection result's first diagnostics carry, in ``extra``, the whole
    :class:`~abrupt.detect.orbit.analysis.OrbitAnalysis` (``"analysis"``) and every statistic's threshold
    (``"thresholds"``): read them with :func:`orbit_analysis` and :func:`orbit_thresholds`."""

    series_type: ClassVar[type] = Ephemeris
    kind: ClassVar[str] = "unknown"
    statistic: ClassVar[str] = "glr"

    def __init__(
        self,
        *,
        tuning: str = "auto",
        tau_s: float | None = None,
        q_m2_s5: float | None = None,
        sigma_pos_m: float | None = None,
        sigma_vel_mps: float | None = None,
        dynamics: str | None = None,
        gravity_degree: int = DEFAULT_GRAVITY_DEGREE,
        null: Ephemeris | None = None,
        confidence_z: float = 1.0,
        kind: str | None = None,
        spacecraft: str | None = None,
        run_id: str = "",
        nuisance: bool = False,
    ) -> None:
        if tuning not in TUNINGS:
            raise ValueError(f"tuning must be one of {TUNINGS}, got {tuning!r}")
        if dynamics is not None and dynamics not in DYNAMICS:
            raise ValueError(f"dynamics must be one of {tuple(DYNAMICS)}, got {dynamics!r}")
        if confidence_z < 0:
            raise ValueError("confidence_z must be non-negative")
        if gravity_degree < 2:
            raise ValueError("gravity_degree must be at least 2")
        self.tuning = tuning
        self.tau_s = tau_s
        self.q_m2_s5 = q_m2_s5
        self.sigma_pos_m = sigma_pos_m
        self.sigma_vel_mps = sigma_vel_mps
        self.dynamics = dynamics
        self.gravity_degree = gravity_degree
        self.confidence_z = confidence_z
        self.nuisance = nuisance
        self.event_kind = kind or type(self).kind
        self.spacecraft = spacecraft
        self.run_id = run_id
        self._null = null
        #: thresholds to use instead of calibrating (a later scan of the same arc keeps the first's)
        self.fixed_thresholds: dict[str, Threshold] | None = None
        #: filter tuning and settings to use instead of deriving them from the series (a later scan of the
        #: same arc keeps the first's; a calibration block of a long span is tuned on the block alone)
        self.fixed_config: OrbitDetectorConfig | None = None
        #: epochs (of the series given to :meth:`detect`) whose statistic the self-calibration may use; None:
        #: every evaluated epoch. A calibration block of a long span calibrates on the epochs its own arc
        #: would test (:mod:`abrupt.pipelines.orbit_blocks`)
        self.calibration_mask: NDArray[np.bool_] | None = None
        #: treat the arc's Earth-shadow passages as known nuisance epochs (:mod:`~abrupt.detect.orbit.boundaries`);
        #: off where the threshold's null already holds them (thresholds pooled over a product's satellites)
        self.eclipses = True

    def __reduce__(self) -> tuple[Any, ...]:
        # the registered classes are made by ``type`` below, not module attributes: pickle (for the worker
        # processes of a long run) rebuilds one from its registered name
        return (_rebuild, (self.name, dict(vars(self))))

    def config(self) -> dict[str, Any]:
        out = super().config()
        out["null"] = self._null is not None
        # how a calibration block or a later scan is run, not a setting of the detector
        out.pop("fixed_config", None)
        out.pop("calibration_mask", None)
        return out

    # ------------------------------------------------------------------ configuration
    def detector_config(self, eph: Ephemeris, budget: FalseAlarmBudget) -> OrbitDetectorConfig:
        """Filter tuning and detector settings for ``eph`` (auto tuning reads the data itself), or
        ``fixed_config`` when set."""
        if self.fixed_config is not None:
            return replace(self.fixed_config, budget=budget)
        dyn = self.dynamics or ("field" if self.tuning == "auto" else "two-body")
        zonal = max(0, DYNAMICS[dyn])
        degree = self.gravity_degree if dyn == "field" else 0
        if self.tuning == "auto":
            fc, s_pos, s_vel = auto_tune(eph, zonal_degree=zonal, gravity_degree=degree, third_body=degree > 0)
            # the filters converge within ~20 τ; capped at 6 h so that sparse arcs (CPF predictions at
            # 5-15 min, τ = 10 steps) keep most of their epochs (unchanged for 60 s data: 20 τ = 3.3 h)
            settle = max(min(20.0 * fc.tau_s, SETTLE_CAP_S), 30.0 * eph.nominal_step_s)
        else:
            fc = FilterConfig(zonal_degree=zonal, gravity_degree=degree, third_body=degree > 0)
            s_pos, s_vel, settle = 10.0, 0.25, 1800.0
        if self.tau_s is not None:
            fc = replace(fc, tau_s=self.tau_s)
        if self.q_m2_s5 is not None:
            fc = replace(fc, q_rtn_m2_s5=(self.q_m2_s5,) * 3)
        if self.nuisance:
            forces = nuisance_force_model(degree, degree > 0, zonal)
            fc = replace(fc, forces=forces, nuisance=NuisanceConfig())
        return OrbitDetectorConfig(
            filter=fc,
            sigma_pos_m=self.sigma_pos_m if self.sigma_pos_m is not None else float(s_pos),
            sigma_vel_mps=self.sigma_vel_mps if self.sigma_vel_mps is not None else float(s_vel),
            settle_s=settle,
            statistic=self.statistic,
            budget=budget,
            kind=self.event_kind,
            orbital_constants=self.statistic in ("d_sma", "d_ecc", "d_hdir"),
        )

    # ------------------------------------------------------------------ detection
    def detect(self, series: Ephemeris, budget: FalseAlarmBudget) -> DetectionResult:
        if len(series) < 10:
            return DetectionResult.empty(warnings=(f"{len(series)} epochs: too few to filter",))
        return self.detect_analysis(series, budget, self.analyse(series, budget))

    def analyse(self, series: Ephemeris, budget: FalseAlarmBudget) -> OrbitAnalysis:
        """The filters, fusion and every statistic of ``series`` with this detector's settings."""
        cfg = self.detector_config(series, budget)
        span_s = float((series.times_utc[-1] - series.times_utc[0]) / np.timedelta64(1, "s"))
        if span_s < 2.0 * cfg.settle_s + series.nominal_step_s:
            raise ArcTooShortError(
                f"the arc spans {span_s / 3600:.3g} h but the filter ({self.tuning} tuning) needs "
                f"{cfg.settle_s / 3600:.3g} h to settle at each end: no epoch could be tested; give at least "
                f"{(2 * cfg.settle_s + series.nominal_step_s) / 3600:.3g} h of data",
                file=series.source,
            )
        try:
            return analyse(series, cfg)
        except np.linalg.LinAlgError:
            dyn = self.dynamics or ("field" if self.tuning == "auto" else "two-body")
            raise InputError(
                f"the orbit filter diverged on this arc ({self.tuning} tuning, {dyn} dynamics): its innovation "
                "covariance became singular, the model cannot follow these positions; try --tuning auto or "
                "--dynamics field",
                file=series.source,
            ) from None

    def detect_analysis(self, series: Ephemeris, budget: FalseAlarmBudget, analysis: OrbitAnalysis) -> DetectionResult:
        """Thresholds (``fixed_thresholds``, the null, or the arc itself), product boundaries and events of an
        analysis made by :meth:`analyse`."""
        if self.fixed_thresholds is not None:
            thresholds = dict(self.fixed_thresholds)
        elif self._null is not None:
            null = analyse(self._null, analysis.config)
            thresholds = calibrate_thresholds(null.statistics, sample_rate_hz=null.sample_rate_hz, budget=budget)
        else:
            thresholds = self_calibrate(self._calibration_view(analysis), budget=budget, confidence_z=self.confidence_z)
        warnings: tuple[str, ...] = ()
        if self.statistic not in thresholds:
            warnings = (
                f"too few event-free epochs to set a threshold for {self.statistic}; "
                "give a longer arc or event-free data (null)",
            )
            return DetectionResult.empty(warnings=warnings, diagnostics=self._diagnostics(analysis, thresholds))
        boundaries, searched = self._boundaries(analysis, thresholds, budget)
        chash = config_hash({**self.config(), "budget": str(budget)})
        events = find_events(
            searched, thresholds, spacecraft=self.spacecraft or series.satellite, run_id=self.run_id, cfg_hash=chash
        )
        # a position jump no velocity change explains is the product's, not a burn
        events, jumps, notes = split_discontinuities(analysis, events, thresholds[self.statistic].value)
        boundaries = sorted([*boundaries, *jumps], key=lambda b: b.index)
        return DetectionResult(events, self._diagnostics(analysis, thresholds, boundaries), (*warnings, *notes))

    def _boundaries(
        self, analysis: OrbitAnalysis, thresholds: dict[str, Threshold], budget: FalseAlarmBudget
    ) -> tuple[list[ProductBoundary], OrbitAnalysis]:
        """Day boundaries, stated joins and Earth-shadow passages treated as nuisance
        (:mod:`abrupt.detect.orbit.boundaries`), and the analysis to search for events (the nuisance windows
        blanked). When the arc shows a pattern, the self-calibrated thresholds are set again without the
        nuisance windows (in place)."""
        name = self.statistic
        calibrating = self._null is None and self.fixed_thresholds is None

        def judged(h: float) -> tuple[list[ProductBoundary], FloatArray]:
            return product_boundaries(analysis, h, budget, name, eclipses=self.eclipses)

        boundaries, blanked = judged(thresholds[name].value)
        if calibrating and self.eclipses and not any(b.kind == SHADOW for b in boundaries):
            # shadow passages inflate a tail fit that holds them: judge them against the level of the rest
            mask = eclipse_mask(analysis)
            if mask.any() and not mask.all():
                own = self._calibration_view(analysis).statistics[name]
                quiet = replace(analysis, statistics={name: np.where(mask, np.nan, own)})
                level = self_calibrate(quiet, budget=budget, confidence_z=self.confidence_z, names=(name,)).get(name)
                trial = judged(level.value) if level is not None else ([], blanked)
                if any(b.kind == SHADOW for b in trial[0]):
                    boundaries, blanked = trial
        if not boundaries:
            return [], analysis
        if calibrating:
            mask = boundary_mask(analysis, boundaries)
            own_all = self._calibration_view(analysis).statistics
            quiet_all = {k: np.where(mask, np.nan, v) for k, v in own_all.items()}
            thresholds.update(
                self_calibrate(replace(analysis, statistics=quiet_all), budget=budget, confidence_z=self.confidence_z)
            )
            boundaries, blanked = judged(thresholds[name].value)
        return boundaries, replace(analysis, statistics={**analysis.statistics, name: blanked})

    def _calibration_view(self, analysis: OrbitAnalysis) -> OrbitAnalysis:
        """The analysis with every statistic outside ``calibration_mask`` blanked (as given without one)."""
        mask = self.calibration_mask
        if mask is None:
            return analysis
        if mask.shape != analysis.t_s.shape:
            raise ValueError(f"calibration mask has {mask.shape} epochs, the analysis {analysis.t_s.shape}")
        return replace(analysis, statistics={k: np.where(mask, v, np.nan) for k, v in analysis.statistics.items()})

    def _diagnostics(
        self, analysis: OrbitAnalysis, thresholds: dict[str, Threshold], boundaries: Sequence[ProductBoundary] = ()
    ) -> tuple[Diagnostics, ...]:
        cfg = analysis.config
        noise = {
            "tau_s": cfg.filter.tau_s,
            "q_m2_s5": cfg.filter.q_rtn_m2_s5[0],
            "sigma_pos_m": cfg.sigma_pos_m,
            "sigma_vel_mps": cfg.sigma_vel_mps,
            "innovation_scale": innovation_scale(analysis),
        }
        epoch = analysis.ephemeris.times_utc[0]
        out = [
            Diagnostics(
                name=f"orbit.{self.statistic}",
                time_s=analysis.t_s,
                statistic=analysis.statistics[self.statistic],
                threshold=thresholds.get(self.statistic),
                epoch_utc=epoch,
                unit="",
                noise_model=noise,
                extra={
                    "analysis": analysis,
                    "thresholds": dict(thresholds),
                    "product_boundaries": [b.as_dict() for b in boundaries],
                },
            )
        ]
        for key, values in analysis.statistics.items():
            if key != self.statistic and np.isfinite(values).any():
                out.append(Diagnostics(f"orbit.{key}", analysis.t_s, values, thresholds.get(key), epoch))
        return tuple(out)


#: ``orbit.<statistic>`` → its class: :class:`OrbitDetector` with the statistic set (defining each
#: subclass registers it).
ORBIT_DETECTORS: dict[str, type[OrbitDetector]] = {
    f"orbit.{statistic}": type(
        f"OrbitDetector_{statistic}",
        (OrbitDetector,),
        {"name": f"orbit.{statistic}", "statistic": statistic, "summary": summary, "__module__": __name__},
    )
    for statistic, summary in STATISTIC_SUMMARIES.items()
}


def _rebuild(name: str, state: dict[str, Any]) -> OrbitDetector:
    """The detector ``name`` (a key of :data:`ORBIT_DETECTORS`) with the attributes ``state``."""
    cls = ORBIT_DETECTORS[name]
    detector = cls.__new__(cls)
    detector.__dict__.update(state)
    return detector


def orbit_analysis(result: DetectionResult) -> OrbitAnalysis | None:
    """The filters, fusion and statistics an orbit detector computed (None when it had too few epochs)."""
    for d in result.diagnostics:
        analysis = d.extra.get("analysis")
        if isinstance(analysis, OrbitAnalysis):
            return analysis
    return None


def orbit_thresholds(result: DetectionResult) -> dict[str, Threshold]:
    """Every statistic's threshold, in the order they were set (empty when none could be set)."""
    for d in result.diagnostics:
        thresholds = d.extra.get("thresholds")
        if isinstance(thresholds, dict):
            return dict(thresholds)
    return {}


def orbit_product_boundaries(result: DetectionResult) -> list[dict[str, object]]:
    """The product's day boundaries the detector treated (time, peak, bound, raised); empty when the
    product shows no discontinuity pattern."""
    for d in result.diagnostics:
        found = d.extra.get("product_boundaries")
        if isinstance(found, list):
            return list(found)
    return []
