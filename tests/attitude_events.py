"""Attitude events as the flight pipeline writes them, for the tests of what reads them (orbit evidence,
reports): one place for the columns every such event carries."""

from __future__ import annotations

from abrupt.events import Event

ATTRIBUTED = {"kind_confidence": 0.9, "kind_channel": "", "kind_reason": "impulsive external step"}


def attitude_event(
    kind: str, time_utc: str, *, dh_x_Nms: float = 0.05, attributed: bool = True, **extra: float
) -> Event:
    """One ``attitude.flight_glr`` event of spacecraft SC-Z with ΔH along N x; ``attributed`` adds the
    attribution columns (a confident ``impulsive external step``), ``extra`` further columns."""
    return Event(
        spacecraft="SC-Z",
        kind=kind,
        detector="attitude.flight_glr",
        time_utc=time_utc,
        statistic=50.0,
        threshold=10.0,
        false_alarms_per_day=1.0,
        run_id="r",
        config_hash="c",
        time_sigma_s=1.0,
        dH_N_x_Nms=dh_x_Nms,
        dH_N_y_Nms=0.0,
        dH_N_z_Nms=0.0,
        extra={**(ATTRIBUTED if attributed else {}), **extra},
    )
