"""Options shared by the ``detect`` commands: the false-alarm budget and detector names from the registry.

Every ``detect`` command takes the budget the same way: ``--false-alarms TEXT`` read by
:meth:`abrupt.thresholds.FalseAlarmBudget.parse` (``1/day``, ``1/week``, ``0.1/year``), with
``--false-alarms-per-day``, ``--false-alarms-per-week`` and ``--false-alarms-per-year`` kept as
aliases that map to it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module

if TYPE_CHECKING:
    from abrupt import thresholds
else:
    thresholds = lazy_module("abrupt.thresholds")


#: The default budget of the flight pipeline (a telemetry ``--store``): its step detector's stated rate
#: (``abrupt.detect.attitude.flight_glr.FlightGlrDetector.STATED_RATE``; a test holds them equal). Every
#: command that runs the flight pipeline (detection, injection recovery, fleet store rows) defaults to it,
#: so that a recovery study measures the efficiency at the threshold the detection uses.
FLIGHT_STORE_BUDGET = "0.1/day"

BUDGET_KEYS = ("false_alarms", "false_alarms_per_day", "false_alarms_per_week", "false_alarms_per_year")


def budget_options(default: str = "1/day") -> Callable[[Any], Any]:
    """Decorator adding ``--false-alarms`` and its per-day/week/year aliases to a command."""

    def wrap(f: Any) -> Any:
        for unit in ("year", "week", "day"):
            f = click.option(
                f"--false-alarms-per-{unit}",
                f"false_alarms_per_{unit}",
                type=click.FloatRange(min=0.0, min_open=True),
                default=None,
                help=f"Alias of --false-alarms N/{unit}.",
            )(f)
        return click.option(
            "--false-alarms",
            "false_alarms",
            default=None,
            metavar="RATE",
            help=f"False-alarm budget the thresholds are set for: '1/day', '1/week', '0.1/year' [default: {default}].",
        )(f)

    wrap.default = default  # type: ignore[attr-defined]
    return wrap


def budget_given(options: dict[str, Any]) -> bool:
    """Whether the command line named a budget (any of the budget options)."""
    return any(options.get(k) is not None for k in BUDGET_KEYS)


def pop_budget(options: dict[str, Any], default: str = "1/day") -> thresholds.FalseAlarmBudget:
    """Remove the budget options from a command's keyword arguments and return the one budget they give."""
    given = {k: options.pop(k, None) for k in BUDGET_KEYS}
    chosen = {k: v for k, v in given.items() if v is not None}
    if len(chosen) > 1:
        names = ", ".join("--" + k.replace("_", "-") for k in chosen)
        raise click.UsageError(f"give the false-alarm budget once; got {names}")
    if not chosen:
        return thresholds.FalseAlarmBudget.parse(default)
    key, value = next(iter(chosen.items()))
    if key == "false_alarms":
        try:
            return thresholds.FalseAlarmBudget.parse(str(value))
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="--false-alarms") from None
    return thresholds.FalseAlarmBudget(float(value), key.removeprefix("false_alarms_per_"))  # type: ignore[arg-type]
