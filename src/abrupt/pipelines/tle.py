"""TLE/OMM maneuver pipeline: read → split per satellite → choose the detector by regime → detect.

No command-line code here (``abrupt.cli.tle`` parses options and writes outputs). A file may hold
many satellites (a catalogue extract, an OMM batch): each is a separate history, detected with
``tle.geo_station_keeping`` when geosynchronous and ``tle.mean_elements`` otherwise (or the detector
named by the caller), with the same :class:`~abrupt.thresholds.FalseAlarmBudget`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt import progress
from abrupt.catalog import AnalysedSpan
from abrupt.detect.base import DetectionResult, Detector, get_detector
from abrupt.detect.tle.detectors import TleMeanElements, detector_for
from abrupt.errors import InputError
from abrupt.events import empty_frame, new_run_id
from abrupt.readers.omm import read_element_histories
from abrupt.readers.tle import ElementHistory
from abrupt.thresholds import FalseAlarmBudget


@dataclass
class SatelliteResult:
    """One satellite of a TLE/OMM run: its history, the detector used and the result."""

    history: ElementHistory
    detector: str
    result: DetectionResult
    spacecraft: str = ""

    @property
    def analysed(self) -> AnalysedSpan | None:
        """The epochs the detector read: first to last element set (None for an empty history)."""
        epochs = self.history.elements["epoch_utc"]
        if len(epochs) == 0:
            return None
        return AnalysedSpan(self.spacecraft, epochs.min(), epochs.max(), self.detector)

    @property
    def events(self) -> pd.DataFrame:
        return self.result.events

    @property
    def noise_model(self) -> dict[str, Any]:
        return dict(self.result.diagnostics[0].noise_model or {}) if self.result.diagnostics else {}


@dataclass
class TleRunResult:
    """All satellites of one input file."""

    path: str
    run_id: str
    satellites: list[SatelliteResult] = field(default_factory=list)

    @property
    def events(self) -> pd.DataFrame:
        frames = [s.events for s in self.satellites if len(s.events)]
        if not frames:
            return empty_frame()
        return pd.concat(frames, ignore_index=True).sort_values("time_utc", kind="stable").reset_index(drop=True)

    @property
    def analysed(self) -> list[AnalysedSpan]:
        """Per satellite, the span of element sets analysed (quiet satellites included)."""
        return [span for s in self.satellites if (span := s.analysed) is not None]

    @property
    def skipped(self) -> list[InputError]:
        return [e for s in self.satellites for e in s.history.skipped]


def satellite_label(history: ElementHistory) -> str:
    """``NAME (NORAD n)`` when the file names the satellite, else ``NORAD-n``."""
    return f"{history.name} ({history.norad_id})" if history.name else f"NORAD-{history.norad_id}"


def detect_tle_file(
    path: str | Path,
    budget: FalseAlarmBudget,
    *,
    detector: str = "auto",
    norad_id: int | None = None,
    strict: bool = False,
    spacecraft: str | None = None,
    all_candidates: bool = False,
    run_id: str | None = None,
    settings: dict[str, Any] | None = None,
) -> TleRunResult:
    """Detect maneuvers in every satellite of a TLE/3LE/OMM file (or only ``norad_id``).

    ``detector``: ``auto`` (by regime), ``tle.mean_elements`` or ``tle.geo_station_keeping``.
    ``spacecraft`` overrides the name written in the events (only with one satellite).
    Malformed element sets are skipped and reported unless ``strict``.
    """
    run_id = run_id or new_run_id()
    histories = read_element_histories(path, strict=strict)
    if norad_id is not None:
        histories = [h for h in histories if h.norad_id == norad_id]
        if not histories:
            raise InputError(f"no element sets of satellite {norad_id}", file=path, line=1)
    if spacecraft is not None and len(histories) > 1:
        raise InputError(
            f"{len(histories)} satellites in the file: a single spacecraft name cannot be given to all; "
            "select one with norad_id",
            file=path,
            line=1,
        )
    out = TleRunResult(str(path), run_id)
    for history in progress.track(histories, "satellites", unit="satellite"):
        name = spacecraft or history.name or f"NORAD-{history.norad_id}"
        kwargs = dict(settings or {})
        kwargs.update(all_candidates=all_candidates, spacecraft=name)
        det: Detector[Any]
        if detector == "auto":
            det = detector_for(history, run_id=run_id, **kwargs)
        else:
            cls = get_detector(detector, "tle")
            if issubclass(cls, TleMeanElements):  # a plug-in tle detector may not take a run_id
                kwargs["run_id"] = run_id
            det = cls(**kwargs)
        out.satellites.append(SatelliteResult(history, det.name, det.detect(history, budget), name))
    return out


def cross_track_mps(truth: pd.DataFrame) -> NDArray[np.float64]:
    """Per operator line, its cross-track ΔV (m/s) judged against the floor: the sum of its burns'
    magnitudes (``dv_n_abs_mps``) where the file gives it, else the net |``dv_n_mps``| (NaN: none)."""
    dv_n = np.abs(truth["dv_n_mps"].to_numpy(dtype=float)) if "dv_n_mps" in truth else np.full(len(truth), np.nan)
    if "dv_n_abs_mps" in truth:
        summed = truth["dv_n_abs_mps"].to_numpy(dtype=float)
        dv_n = np.where(np.isfinite(summed), summed, dv_n)
    return dv_n


def burns_above_floor(truth: pd.DataFrame, detectable_by_year: list[dict[str, Any]]) -> NDArray[np.bool_]:
    """Per operator burn: is it at or above the floor the run states for its year?

    A burn is above when its in-track |ΔV| reaches the year's smallest detectable in-track ΔV or its
    cross-track ΔV the cross-track one (``noise_model["detectable_by_year"]``). The cross-track ΔV is
    the sum of the burns' magnitudes where the file gives it (``dv_n_abs_mps``): a pair of opposite
    burns half an orbit apart (a plane change split over two nodes) turns the orbit normal by both,
    though its summed components net to zero; else the net |``dv_n_mps``|. The in-track ΔV is the
    net (the step of ``a`` follows the sum). A burn whose file gives no ΔV (Fengyun windows) cannot be
    judged and counts as above; a burn in a year the history does not cover counts as below (nothing
    could see it).
    """
    out = np.zeros(len(truth), dtype=bool)
    if not detectable_by_year or len(truth) == 0:
        return out
    by_year = {int(r["year"]): r for r in detectable_by_year}
    times = pd.to_datetime(truth["time_utc"].astype(str), utc=True)
    dv_t = truth["dv_t_mps"].to_numpy(dtype=float) if "dv_t_mps" in truth else np.full(len(truth), np.nan)
    dv_n = cross_track_mps(truth)
    for k, t in enumerate(times):
        row = by_year.get(int(t.year))
        if row is None:
            continue
        if not (np.isfinite(dv_t[k]) or np.isfinite(dv_n[k])):
            out[k] = True
            continue
        t_ok = np.isfinite(dv_t[k]) and abs(dv_t[k]) >= row["min_detectable_dv_t_mps"]
        n_ok = np.isfinite(dv_n[k]) and dv_n[k] >= row["min_detectable_dv_n_mps"]
        out[k] = bool(t_ok or n_ok)
    return out


def burns_below_detectable(truth: pd.DataFrame, detectable_by_year: list[dict[str, Any]]) -> tuple[int, int]:
    """How many of the operator burns with a stated ΔV lie below what the element sets resolve in their
    year: (burns below, burns with a ΔV in a year of the history). A burn is below when its in-track
    |ΔV| is under the year's smallest detectable in-track ΔV and its cross-track ΔV
    (:func:`cross_track_mps`, by magnitude) under the cross-track one
    (``noise_model["detectable_by_year"]`` of the TLE detectors)."""
    if not detectable_by_year or "dv_t_mps" not in truth or "dv_n_mps" not in truth:
        return 0, 0
    by_year = {int(r["year"]): r for r in detectable_by_year}
    below = total = 0
    times = pd.to_datetime(truth["time_utc"].astype(str), utc=True)
    for t, dv_t, dv_n in zip(times, truth["dv_t_mps"], cross_track_mps(truth), strict=True):
        row = by_year.get(int(t.year))
        if row is None or not (np.isfinite(dv_t) or np.isfinite(dv_n)):
            continue
        total += 1
        t_ok = not np.isfinite(dv_t) or abs(dv_t) < row["min_detectable_dv_t_mps"]
        n_ok = not np.isfinite(dv_n) or abs(dv_n) < row["min_detectable_dv_n_mps"]
        below += int(t_ok and n_ok)
    return below, total
