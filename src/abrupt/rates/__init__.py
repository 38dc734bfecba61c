"""Expected rates of detectable strikes (Bennett 2022 ch. 5; Harris 2025 §3.6); see docs/rates.md.

Modules: :mod:`~abrupt.rates.flux` (NASA-90/91 debris, Grün meteoroids with Earth effects),
:mod:`~abrupt.rates.tables` (flux-table format and analytic builders), :mod:`~abrupt.rates.ordem`
(ORDEM 3.x importer), :mod:`~abrupt.rates.mass_models`, :mod:`~abrupt.rates.mef`,
:mod:`~abrupt.rates.geometry` (strike location, effective area), :mod:`~abrupt.rates.montecarlo`,
:mod:`~abrupt.rates.trades` (scenarios, trades, Dask); figures are drawn by :mod:`abrupt.report.rates`.
"""
