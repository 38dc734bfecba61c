"""The event panels and the flight report show the orbit side where the events carry it.

Truth: a synthetic timetable with a known wheel step, and orbit evidence written by hand (a coincident
3 mm/s at +20 s against a 0.2 mm/s floor, nothing above the floor, not covered); the figure is checked
through its artists and texts (matplotlib Agg), not its pixels.
"""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from abrupt.events import events_frame
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.report.attribution import EventPanel, OrbitSide, event_panels_figure
from abrupt.report.flight import orbit_side_html
from abrupt.series.timetable import NS, Timetable
from attitude_events import attitude_event

T0_NS = int(pd.Timestamp("2026-01-05T03:00:00").value)
FLOOR = 2e-4  # [m/s]


def _table(n_wheels: int) -> Timetable:
    """20 min at 1 Hz around T0: identity attitude, the body at rest, one wheel stepping at T0."""
    t = T0_NS + (np.arange(1200) - 600) * NS
    wheels = np.zeros((t.size, n_wheels))
    wheels[t >= T0_NS, 0] = 5.0  # [rad/s]
    q = np.tile([1.0, 0.0, 0.0, 0.0], (t.size, 1))
    return Timetable(
        t, q, np.zeros((t.size, 3)), wheels, np.zeros((t.size, 0)), np.zeros((t.size, 0)), np.ones(t.size, bool)
    )


def _events(**orbit: list[float]) -> pd.DataFrame:
    times = ["2026-01-05T03:00:00.000000Z", "2026-01-05T03:00:00.000000Z", "2026-01-05T03:00:00.000000Z"]
    frame = events_frame(
        [attitude_event(k, t, attributed=False) for k, t in zip(("strike", "unknown", "strike"), times, strict=True)]
    )
    for name, values in orbit.items():
        frame[name] = values
    return frame


ORBIT = {
    "ev_orbit_dv_mps": [3e-3, 0.0, math.nan],
    "ev_orbit_dt_s": [20.0, math.nan, math.nan],
    "ev_orbit_dv_floor_mps": [FLOOR, FLOOR, math.nan],
}


def _texts(fig: plt.Figure) -> list[str]:
    return [t.get_text() for ax in fig.axes for t in ax.texts]


def test_panels_show_the_orbit_side_where_events_carry_it() -> None:
    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    table = _table(sc.wheel_axes.shape[1])
    panels = [EventPanel.from_event(row) for _, row in _events(**ORBIT).iterrows()]
    assert panels[0].orbit == OrbitSide(3e-3, 20.0, FLOOR) and not panels[2].orbit.covered  # type: ignore[union-attr]
    panels.append(EventPanel("no orbit run", T0_NS, np.array([0.05, 0.0, 0.0])))
    fig = event_panels_figure(table, np.zeros((len(table), 3)), sc, panels)
    try:
        assert len(fig.axes) == 5 * 4  # a fifth row: the orbit side
        texts = _texts(fig)
        assert "orbit ΔV 3 mm/s at +20 s (15 × floor 0.2 mm/s)" in texts
        assert "orbit: no ΔV above the floor 0.2 mm/s" in texts
        assert "orbit: not covered by the navigation solution" in texts
        assert "no orbit run given" in texts
        seen = fig.axes[16]  # row 5, column 1 (axes in row-major order)
        assert seen.get_ylabel() == "orbit |ΔV| [mm/s]"
        floor_y = [ln.get_ydata()[0] for ln in seen.lines if ln.get_linestyle() == "--"]
        assert floor_y == [1e3 * FLOOR]
        marker = [ln for ln in seen.lines if ln.get_marker() == "o"]
        assert len(marker) == 1 and marker[0].get_xdata()[0] == 20.0 and marker[0].get_ydata()[0] == 3.0
        assert not [ln for ln in fig.axes[17].lines if ln.get_marker() == "o"]  # nothing above the floor
        assert not fig.axes[18].lines  # not covered: no floor drawn
        # The sensors' rows are still drawn: the wheel's 5 rad/s step shows in row 2.
        assert any(np.nanmax(np.abs(ln.get_ydata())) > 0 for ln in fig.axes[4].lines)
    finally:
        plt.close(fig)


def test_panels_without_orbit_evidence_have_no_orbit_row() -> None:
    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    table = _table(sc.wheel_axes.shape[1])
    panels = [EventPanel.from_event(row) for _, row in _events().iterrows()]
    assert all(p.orbit is None for p in panels)
    fig = event_panels_figure(table, np.zeros((len(table), 3)), sc, panels)
    try:
        assert len(fig.axes) == 4 * 3
        assert not any("orbit" in t for t in _texts(fig))
        assert not any("orbit" in ax.get_ylabel() for ax in fig.axes)
    finally:
        plt.close(fig)


def test_flight_report_lists_the_orbit_side_of_each_event() -> None:
    html = orbit_side_html(_events(**ORBIT))
    assert html.startswith("<h2>Orbit side</h2>") and html.count("</tr>") == 4  # header and three events
    assert "orbit ΔV 3 mm/s at +20 s" in html and "not covered by the navigation solution" in html
    assert orbit_side_html(_events()) == ""
    # As read back from a CSV events file: the empty cells are text.
    as_text = _events(**ORBIT).astype({c: object for c in ORBIT})
    as_text.loc[2, list(ORBIT)] = ""
    assert "not covered" in orbit_side_html(as_text)
