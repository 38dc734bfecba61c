"""Attribution of the flight pipeline's events: evidence columns and the physical class in ``kind``.

:func:`abrupt.pipelines.flight.process_span` computes the evidence of every peak
(:func:`abrupt.detect.attitude.evidence.event_evidence`) while it still holds the chunk's telemetry;
this module joins it to the events above the threshold, classifies each
(:func:`abrupt.detect.attitude.attribution.classify`) and writes ``kind`` (``strike``,
``sensor_fault``, ``external_non_strike``, ``internal`` or ``unknown``), ``kind_confidence``,
``kind_channel`` (the faulty channel of a sensor fault), ``kind_reason`` and the ``ev_*`` columns.
The event identifier includes the kind, so it is recomputed.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from abrupt.detect.attitude.attribution import AttributionRules, classify
from abrupt.detect.attitude.evidence import EventEvidence
from abrupt.events import format_time_utc, make_event_id

ATTRIBUTION_COLUMNS = ("kind_confidence", "kind_channel", "kind_reason")


def attribute_events(
    events: pd.DataFrame, evidence: Mapping[int, EventEvidence], rules: AttributionRules | None = None
) -> pd.DataFrame:
    """``events`` with ``kind`` from the rules and the evidence columns (events without evidence: unknown)."""
    if not len(events):
        out = events.copy()
        for c in (*ATTRIBUTION_COLUMNS, *EventEvidence().as_dict()):
            out[c] = pd.Series(dtype="string" if c in ("kind_channel", "kind_reason") else "float64")
        return out
    by_time = {format_time_utc(np.datetime64(t, "ns")): e for t, e in evidence.items()}
    rows = []
    for t in events["time_utc"].astype(str):
        ev = by_time.get(t, EventEvidence())
        a = classify(ev, rules)
        rows.append(
            {
                "kind": a.kind,
                "kind_confidence": a.confidence,
                "kind_channel": a.channel,
                "kind_reason": a.reason,
                **ev.as_dict(),
            }
        )
    extra = pd.DataFrame(rows, index=events.index)
    out = events.copy()
    out["kind"] = extra.pop("kind").astype(out["kind"].dtype)
    for c in extra.columns:
        out[c] = extra[c].astype("string") if c in ("kind_channel", "kind_reason") else extra[c]
    out["event_id"] = [
        make_event_id(str(r.spacecraft), str(r.detector), str(r.kind), str(r.time_utc), str(r.config_hash))
        for r in out.itertuples()
    ]
    out["event_id"] = out["event_id"].astype(events["event_id"].dtype)
    return out
