"""From detected strikes to the debris and meteoroid environment (docs/flux-inference.md).

Modules: :mod:`~abrupt.flux.exposure` (detection efficiency, exposure per spacecraft-day, its catalog
table), :mod:`~abrupt.flux.forward` (expected detected events per |ΔH| and direction bin from the rates
package's fluxes and geometry), :mod:`~abrupt.flux.inference` (Poisson likelihood, maximum likelihood,
profile-likelihood intervals, upper limits, goodness of fit) and :mod:`~abrupt.flux.showers` (meteoroid
shower calendar and the association test).
"""
