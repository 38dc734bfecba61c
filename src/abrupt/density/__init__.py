"""Thermospheric density from satellite drag and meteoroid ablation (Close & Li 2015).

ρB from TLE histories (:mod:`abrupt.density.tle_drag`)
------------------------------------------------------

Slide "Data" (Picone et al. 2005)::

    Δn̄ = (3/2) μ^(−2/3) ∫ n̄^(1/3) ρ B v³ F dt,   K = ρ̄B̄ ≅ 2 μ^(2/3) Δn̄ / (3 ∫ n̄^(1/3) v³ F dt),

B = C_D A/m, F = |v_rel|(v_rel·v̂)/v² with v_rel = v − ω⊕ × r (atmosphere co-rotating). These follow from the
along-track drag −½ρBv²F and dn/dt = −(3/2)(n/a) da/dt; the slide's line "da/dt = 2a²Bv³F/μ" lacks ρ and the
factor −½ (erratum; the Δn̄ line is consistent).

1. Each element set initialises SGP4 (abrupt's TLE reader, WGS-72); between consecutive sets the orbit is
   propagated from the earlier set on an even grid of `nodes_per_rev` (9.5) nodes a revolution of that set's
   orbit (2π/n̄), and I(t) = ∫ n̄^(1/3) v³F dt is accumulated (trapezoid rule; "Integration nodes" below).
   `step_s` (s), when set, is a fixed spacing instead (the old default was 600 s).
2. Windows on a common UTC grid (`--interval-days`); each uses the sets inside it and the two bracketing sets. K
   is the least-squares slope of n̄ against (3/2)μ^(−2/3) I — with two sets exactly the slide's formula, with
   more it uses them all.
3. Gaps holding a maneuver are removed: the history is cut at maneuvers found by abrupt's TLE maneuver detector
   (`abrupt.detect.tle.maneuvers.detect_tle_maneuvers`), at gaps longer than `max_gap_days` (3), and at any gap
   where n̄ *falls* by more than 4·√2·σ_n̄ (drag only raises n̄: an orbit raise the detector missed). Inside a
   window each piece gets its own n̄ offset and one common K.
4. σ_n̄ is the history's own mean-motion noise, 1.4826·MAD of each set's residual to the line through its
   neighbours; sets more than 6σ off (bad fits) are rejected and counted. σ_K is the larger of the white-noise
   value and the window's residual scatter (TLE errors are correlated).
5. K < −3σ_K ("negative decay") is kept in the table with `status = negative decay` and counted, and not used
   downstream. Windows with too few sets or covering < 50 % of the window are counted.
7. Physical bounds (`abrupt.density.drag_plausibility`). The largest ballistic coefficient is B_max = 100 m²/kg:
   intact objects have 0.001-0.1 m²/kg, high area-to-mass MLI debris in GEO 10-30 m²/kg (Schildknecht 2007); 100
   leaves room for the model density being a few times low. *Per object, before any propagation*: the fastest
   decay drag could cause at the lowest perigee a(1 − e) − R⊕ of the history, dn̄/dt ≤ (3/2) n v_p F_max ρ_max
   B_max, with ρ_max the largest NRLMSIS 2.1 density at that altitude (F10.7 = F10.7a = 300 sfu, Ap = 400, over
   latitude and local time) and F_max = 1 − 2x cos i + x², x = ω⊕ r_p / v_p (|v_rel|²/v²: an orbit co-rotating
   with the atmosphere, geostationary, feels almost no drag), over the longest span a window can use
   (`interval_days` + 2 `max_gap_days`), is compared with the history's mean-motion noise σ_n̄ (from the
   elements, in time). Below it no window can hold a drag signal: the object gets no windows, and the reason `no
   drag signal above N km (perigee P km)` (N: the lowest altitude where the bound falls to σ_n̄, circular orbits
   at the object's largest inclination) is counted and printed. *Per window*, with a model density: a window
   whose K − 3σ_K exceeds B_max·ρ̄_M would need B above B_max; its status is `implausible ballistic
   coefficient`, counted, and not used by the order statistics or the report (the joint fit reads the element
   sets, not the windows). The command prints `N object(s) skipped: no drag signal; M window(s) refused:
   implausible ballistic coefficient` (with `--windows-only`, for the files run now; the first objects are
   listed as `skipped:` lines).
6. With a model (`with_model`), NRLMSIS is evaluated on every second node (with `model_grid`, from the shared
   grid on every node, above) and log ρ is interpolated by a cubic spline in time. Linear interpolation cut the
   orbital oscillation of log ρ (error (hω)²/8 ≈ 23 % of it at 4.6 samples a revolution): on the simulated
   constellation the model density along each orbit came out 1.8 % low on average, 0.6 % with the spline (0.3 %
   with NRLMSIS on every node, twice the cost).

With the model, ρ̄_M = ∫ n̄^(1/3) v³F ρ_MSIS dt / ∫ n̄^(1/3) v³F dt on the same grid (NRLMSIS every second node,
log-interpolated), so K/ρ̄_M = B·(ρ/ρ_M) is directly comparable across altitudes.

Integration nodes
-----------------

The integrand n̄^(1/3) v³F (and ρ_M with the model) is periodic with the orbit, so the node spacing is set per
gap in revolutions, not seconds: at most 2π/n̄ / `nodes_per_rev` × (1 − e)^(3/2)/(1 + e)^(1/2). The factor is
the time a radian of anomaly takes at perigee over its mean (Kepler's second law): an eccentric orbit's perigee
pass, where v³ and the density peak, gets the nodes a circular orbit's revolution gets
(`abrupt.density.tle_drag.gap_node_counts`). A fixed 600 s step gave a low orbit ≈ 9.5 nodes a revolution and a
geostationary one 144; now every orbit gets 9.5 (LEO the same, deep orbits far fewer). A half integer on
purpose: the direct NRLMSIS sampling (every second node, spline in log ρ) then drifts in orbital phase from one
revolution to the next, as it did at 600 s; at exactly 10 (5 samples a revolution, phase-locked) its
interpolation error added up instead of averaging out (stride 2 against every node, catalogue-00015, LEO
windows: p99 2.6 σ, 546 windows above 1 σ; 9.5: p99 1.03 σ, 77 above 1 σ; 600 s: 0.99 σ, 72).
`tests/test_tle_drag_nodes.py` checks the counts for known mean motions and the trapezoid rule on those nodes
against the exact mean of (a/r)³ over a Kepler revolution, (1 − e²)^(−3/2), for e = 0-0.7 (within 1e-3; without
the perigee factor 86 % off at e = 0.7).

The number was chosen on one simulated catalogue file (10, then 9.5 for the phase drift above; the 9.5 figures
of the other files were seen when it was chosen) and checked on two other files and on three real LEO histories,
each against a 150 s step, in units of each window's own σ of ρB (the model density: its relative change over
σ_K/|K|): `python benchmarks/bench_density_nodes.py` (figures in `docs/results/bench_density_nodes.txt` and
`docs/results/bench_catalogue_scale_density.txt`). ρB itself moves by ≤ 0.002 σ at 8-12 nodes a revolution; the model
density is what needs the nodes (8: up to 0.68 σ; 9.5: ≤ 0.26 σ, p99 ≤ 0.095 σ, like the 600 s step's 0.26 σ and
0.094 σ). Simpson's rule on the same nodes was worse for the model density (p99 0.65-0.95 σ at 8 nodes; the
half-density sub-grid aliases the diurnal harmonics) and was not kept. Near-geostationary objects are the
exception: the atmosphere co-rotates with them, F ≈ 0, so ΔI is a difference of near-equal terms and their
windows (no drag signal) move by up to 19 σ at 9.5 nodes a revolution (0.12 σ at 600 s); such objects have no
measurable drag at all and are for the no-drag-signal rule to skip, or for `step_s` to integrate finely.
"""
