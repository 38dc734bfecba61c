"""The realised false-alarm rate of ``abrupt detect tle`` on the satellite's own null, printed beside
the budget: pooled over the history, or era by era with one line per calendar year."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module

if TYPE_CHECKING:
    import pandas as pd

    from abrupt.simulate import tle_injection as simulate_tle_injection
    from abrupt.simulate import tle_own_null as simulate_tle_own_null
else:
    pd = lazy_module("pandas")
    simulate_tle_injection = lazy_module("abrupt.simulate.tle_injection")
    simulate_tle_own_null = lazy_module("abrupt.simulate.tle_own_null")


def measure(sat: Any, budget: Any, seeds: int, pooled_years: float | None, settings: dict[str, Any]) -> dict[str, Any]:
    """The own-null measurement for the noise model: era by era (``own_null_by_year``) or, with
    ``pooled_years``, pooled over the history (``own_null``); empty when skipped or impossible."""
    if pooled_years is None:
        by_year = own_null_by_year(sat, budget, seeds, settings)
        return {} if by_year is None else {"own_null_by_year": by_year}
    pooled = own_null(sat, budget, seeds, pooled_years, settings)
    return {} if pooled is None else {"own_null": pooled}


def own_null(sat: Any, budget: Any, seeds: int, years: float, settings: dict[str, Any]) -> dict[str, Any] | None:
    """Measure and print the false-alarm rate realised on the satellite's own bootstrapped quiet noise
    (quiet: away from its detections) beside the budget; None when skipped or impossible."""
    if seeds == 0:
        return None
    if len(sat.history) < (least_sets := simulate_tle_injection.MIN_ELEMENT_SETS):
        click.echo(
            f"  own null: {len(sat.history)} element sets, too few (at least {least_sets})",
            err=True,
        )
        return None
    found = sat.events.loc[sat.events["statistic"] >= sat.events["threshold"]] if len(sat.events) else sat.events
    known = list(pd.to_datetime(found["time_utc"].astype(str), utc=True).dt.tz_localize(None)) if len(found) else []
    kw = {k: v for k, v in settings.items() if v is not None}
    try:
        rate = simulate_tle_own_null.own_null_rate(sat.history, known, budget, years=years, seeds=range(seeds), **kw)
    except ValueError as exc:
        click.echo(f"  own null: not measured ({exc})", err=True)
        return None
    lo, hi = rate.interval_per_year()
    click.echo(
        f"  own null: {rate.false_alarms} false alarm(s) in {rate.sat_years:.1f} satellite-years of its own quiet "
        f"noise ({rate.histories} bootstrapped histories): {rate.rate_per_year:.2f} per year "
        f"(95 % {lo:.2f}-{hi:.2f}) against the budget {budget} ({rate.ratio:.2f}x)",
        err=True,
    )
    return rate.as_dict()


def own_null_by_year(sat: Any, budget: Any, seeds: int, settings: dict[str, Any]) -> list[dict[str, Any]] | None:
    """Measure and print the false-alarm rate realised per calendar year on null histories that follow
    the satellite's eras (:func:`abrupt.simulate.tle_own_null.own_null_by_year`; quiet: away from its
    detections) beside the budget; None when skipped or impossible."""
    if seeds == 0:
        return None
    if len(sat.history) < (least_sets := simulate_tle_injection.MIN_ELEMENT_SETS):
        click.echo(f"  own null: {len(sat.history)} element sets, too few (at least {least_sets})", err=True)
        return None
    found = sat.events.loc[sat.events["statistic"] >= sat.events["threshold"]] if len(sat.events) else sat.events
    known = list(pd.to_datetime(found["time_utc"].astype(str), utc=True).dt.tz_localize(None)) if len(found) else []
    kw = {k: v for k, v in settings.items() if v is not None}
    try:
        rows = simulate_tle_own_null.own_null_by_year(sat.history, known, budget, seeds=range(seeds), **kw)
    except ValueError as exc:
        click.echo(f"  own null: not measured ({exc})", err=True)
        return None
    total_fa = sum(r.false_alarms for r in rows)
    total_years = sum(r.sat_years for r in rows)
    lo, hi = simulate_tle_own_null.poisson_interval(total_fa, total_years)
    click.echo(
        f"  own null, era by era ({seeds} bootstrapped histories of its own span, each year's noise and cadence "
        f"its own): {total_fa} false alarm(s) in {total_years:.1f} satellite-years, "
        f"{total_fa / total_years if total_years > 0 else float('nan'):.2f} per year (95 % {lo:.2f}-{hi:.2f}) "
        f"against the budget {budget}",
        err=True,
    )
    for r in rows:
        d = r.as_dict()
        if not r.sat_years > 0:
            click.echo(f"    {r.year}: not measured (no gap of this year clear of block junctions)", err=True)
            continue
        click.echo(
            f"    {r.year}: {r.false_alarms} in {r.sat_years:.2f} satellite-years, realised "
            f"{d['rate_per_year']:.2f} per year (95 % {d['rate_95_lo']:.2f}-{d['rate_95_hi']:.2f}), stated "
            f"{r.budget_per_year:.3g}",
            err=True,
        )
    return [r.as_dict() for r in rows]
