"""The one shape every detector has: a class registered by name, a typed series in, events out.

In the spirit of ruptures (one small class per algorithm, found by name) and maneuver-detect (a
registry of detectors and a frozen output whose "found nothing" has the same shape), a detector is

* a subclass of :class:`Detector` with a class attribute ``name`` of the form
  ``"<capability>.<method>"`` (``attitude.glr``, ``orbit.glr``, ``tle.mean_elements``,
  ``tracking.kaderali_k``, ``mass.inertia_glr``, ...), which registers it on definition;
* configured by keyword arguments to its constructor, validated there;
* called as ``detector.detect(series, budget)`` with the typed series of its capability
  (``series_type``) and a :class:`~abrupt.thresholds.FalseAlarmBudget`;
* returning a :class:`DetectionResult`: the events in the frozen schema of
  :mod:`abrupt.events` (``false_alarms_per_day`` filled from the budget) and typed
  :class:`Diagnostics` (statistic series, the :class:`~abrupt.thresholds.Threshold` with its fit,
  the noise model) that reports read as attributes, as filterpy exposes its innovations.

Adding a detector is one class; the command line lists and runs it by name with no other change::

    class MyDetector(Detector[Telemetry]):
        name = "attitude.my_method"
        series_type = Telemetry
        kind = "strike"

        def detect(self, series: Telemetry, budget: FalseAlarmBudget) -> DetectionResult: ...
"""

from __future__ import annotations

import re
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Generic, TypeVar

import numpy as np
import pandas as pd

from abrupt.events import EVENT_COLUMNS, EVENT_KINDS, empty_frame, run_config_hash
from abrupt.thresholds import FalseAlarmBudget, Threshold
from abrupt.types import FloatArray

SeriesT = TypeVar("SeriesT")

DETECTOR_NAME = re.compile(r"^[a-z][a-z0-9_]*\.[a-z][a-z0-9_]*$")


@dataclass(frozen=True)
class Diagnostics:
    """What a detector computed on its way to events, for reports and studies.

    ``time_s`` are the statistic's sample times in seconds from ``epoch_utc``; ``statistic`` the
    values (same length; NaN where not evaluated); ``threshold`` the fitted threshold with its method
    and budget; ``noise_model`` whatever the detector measured of the data's own noise (documented by
    the detector); ``unit`` the unit of the statistic; ``null_sample`` the event-free values the
    threshold was fitted to (for a GEV fit, the block maxima), for Q-Q plots; ``extra`` anything else
    a detector reports (documented by the detector).
    """

    name: str
    time_s: FloatArray
    statistic: FloatArray
    threshold: Threshold | None
    epoch_utc: np.datetime64 | None = None
    unit: str = ""
    noise_model: Any = None
    null_sample: FloatArray | None = None
    extra: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        t = np.asarray(self.time_s, dtype=np.float64)
        s = np.asarray(self.statistic, dtype=np.float64)
        if t.shape != s.shape[:1]:
            raise ValueError(f"diagnostics {self.name!r}: time_s has {t.shape}, statistic {s.shape}")
        object.__setattr__(self, "time_s", t)
        object.__setattr__(self, "statistic", s)


@dataclass(frozen=True)
class DetectionResult:
    """Events (the frozen schema, ordered by time) and the diagnostics that produced them."""

    events: pd.DataFrame
    diagnostics: tuple[Diagnostics, ...] = ()
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        cols = tuple(self.events.columns[: len(EVENT_COLUMNS)])
        if cols != EVENT_COLUMNS:
            raise ValueError(f"events do not follow the schema: first columns {cols}, expected {EVENT_COLUMNS}")

    @classmethod
    def empty(cls, *, warnings: tuple[str, ...] = (), diagnostics: tuple[Diagnostics, ...] = ()) -> DetectionResult:
        return cls(empty_frame(), diagnostics, warnings)

    def diagnostic(self, name: str) -> Diagnostics:
        for d in self.diagnostics:
            if d.name == name:
                return d
        raise KeyError(f"no diagnostics named {name!r}; have {[d.name for d in self.diagnostics]}")


class Detector(ABC, Generic[SeriesT]):
    """Base class of every detector; a subclass with a ``name`` registers itself.

    Subclasses set ``name`` (``capability.method``), ``series_type`` (the typed series they read),
    ``kind`` (the event kind they report by default) and implement :meth:`detect`. Constructor
    keyword arguments are the detector's settings; :meth:`config` returns them for the run record
    and the ``config_hash``.
    """

    name: ClassVar[str] = ""
    series_type: ClassVar[type] = object
    kind: ClassVar[str] = "unknown"
    summary: ClassVar[str] = ""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if cls.name:
            register(cls)

    @property
    def capability(self) -> str:
        return self.name.split(".", 1)[0]

    def config(self) -> dict[str, Any]:
        """The detector's settings: by default its public instance attributes, except ``run_id`` (the run
        a detector works for is not a setting, and the configuration hash must not change between runs)."""
        return {k: v for k, v in vars(self).items() if not k.startswith("_") and k != "run_id"}

    def config_hash_for(self, budget: FalseAlarmBudget) -> str:
        """The ``config_hash`` of this detector's settings at ``budget`` (name, settings and budget)."""
        return run_config_hash(self.config(), budget, detector=self.name)

    @abstractmethod
    def detect(self, series: SeriesT, budget: FalseAlarmBudget) -> DetectionResult:
        """Find events in ``series`` with thresholds set for ``budget``."""


_REGISTRY: dict[str, type[Detector[Any]]] = {}


def register(cls: type[Detector[Any]]) -> type[Detector[Any]]:
    """Add a detector class to the registry (called on subclass definition)."""
    if not DETECTOR_NAME.match(cls.name):
        raise ValueError(f"detector name {cls.name!r} must be '<capability>.<method>' in lower case")
    if cls.kind not in EVENT_KINDS:
        raise ValueError(f"detector {cls.name!r}: kind {cls.kind!r} is not one of {EVENT_KINDS}")
    old = _REGISTRY.get(cls.name)
    if old is not None and (old.__module__, old.__qualname__) != (cls.__module__, cls.__qualname__):
        raise ValueError(f"detector name {cls.name!r} is taken by {old.__module__}.{old.__qualname__}")
    _REGISTRY[cls.name] = cls
    return cls


def _load_builtin() -> None:
    """Import the modules that define the built-in detectors (they register on import)."""
    import abrupt.detect.registry  # noqa: F401  (its imports register the built-in detectors)


def detector_names(capability: str | None = None) -> tuple[str, ...]:
    """Registered detector names, optionally only those of one capability (``attitude``, ``orbit``...)."""
    _load_builtin()
    names = sorted(_REGISTRY)
    if capability is not None:
        names = [n for n in names if n.split(".", 1)[0] == capability]
    return tuple(names)


def get_detector(name: str, capability: str | None = None) -> type[Detector[Any]]:
    """The detector class registered as ``name``; ``method`` alone is accepted with a capability."""
    _load_builtin()
    key = name if "." in name or capability is None else f"{capability}.{name}"
    try:
        cls = _REGISTRY[key]
    except KeyError:
        known = ", ".join(detector_names(capability)) or "none"
        raise KeyError(f"unknown detector {name!r}; registered: {known}") from None
    if capability is not None and key.split(".", 1)[0] != capability:
        raise KeyError(f"detector {name!r} is not an {capability} detector")
    return cls
