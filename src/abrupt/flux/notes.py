"""What a fit with β free measures, said beside its estimates (the docstring of abrupt.flux, "With β free").

A |ΔH| spectrum fixes each population's expected detections s_p·T_p(β); β itself is measured weakly (from
the meteoroids when their scale is fixed at Grün, or from the spectrum's curvature), and a flux scale taken
through it, s_p = D_p / T_p(β), inherits β's spread. On the simulated acceptance fleet (10 Fermi-like
spacecraft for one year, ΔH90 10 mN·m·s, 0.01 false alarms a day: 9 analysed spacecraft-years) the
Cramér-Rao standard deviations are 160 % for the debris scale and 70 % for β, and the mean of the debris
scale's ML estimate is +38 to +199 % high over eight truths while its median is within −1 to +7 % and the
expected debris detections within 5 % at six of them (benchmarks/bench_flux_ridge.py,
benchmarks/bench_flux_coverage.py). The bias falls as 1/exposure: within 5 % from about 155 analysed
spacecraft-years by the first-order (Cox-Snell) term, about 300 extrapolating the measured +17 % at 90.
"""

from __future__ import annotations

#: Analysed spacecraft-years from which a β-free flux scale's mean is within 5 % on the simulated fleet:
#: (first-order term, measured bias extrapolated as 1/exposure).
UNBIASED_YEARS = (155.0, 300.0)

IDENTIFIED_NOTE = (
    "beta free: the data identify s_p·T_p(beta), the expected detections of each population (expected_events), "
    "far better than s_p itself, whose estimate inherits beta's spread (its mean is biased high on small exposures)"
)


def beta_free_note(analysed_years: float) -> str | None:
    """The note for a fit with β free on ``analysed_years`` analysed spacecraft-years: ``None`` from the
    upper figure of :data:`UNBIASED_YEARS` on, else what the exposure falls short of and what to quote."""
    low, high = UNBIASED_YEARS
    if analysed_years >= high:
        return None
    return (
        f"beta free on {analysed_years:.3g} analysed spacecraft-years, below the {low:.0f}-{high:.0f} from which "
        "simulated fleets give a flux scale whose mean is within 5 % (Fermi-like craft, dH90 10 mN·m·s, 0.01 false "
        "alarms a day; a craft with fewer detections a year needs more years): at 9 analysed spacecraft-years the "
        "mean of the debris scale was +38 to +199 % high (Cramér-Rao s.d. 160 %, beta's 70 %), its median within "
        "-1 to +7 %. Quote the identified expected detections s_p·T_p(beta) (expected_events; within 5 % at 6 of "
        "8 simulated truths) or the median, or fix beta from independent data (--fix beta=...)."
    )
