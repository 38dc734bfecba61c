"""Expected rates of detectable strikes (Bennett 2022 ch. 5; Harris 2025 §3.6); see docs/rates.md.

Modules: :mod:`~abrupt.rates.flux` (NASA-90/91 debris, Grün meteoroids with Earth effects),
:mod:`~abrupt.rates.tables` (flux-table format and analytic builders), :mod:`~abrupt.rates.ordem`
(ORDEM 3.x importer), :mod:`~abrupt.rates.mass_models`, :mod:`~abrupt.rates.mef`,
:mod:`~abrupt.rates.geometry` (strike location, effective area), :mod:`~abrupt.rates.montecarlo`,
:mod:`~abrupt.rates.trades` (scenarios, trades, Dask); figures are drawn by :mod:`abrupt.report.rates`.

Use
---

Trade variables: `spacecraft` (paths joined with `;`), `orbit` (`ALT_KM/INC_DEG`), `flux`, `flux_bound` (sigma
shift, e.g. `-2,0,2`), `mass_model`, `mef`, `grid_spacing` (switches to the point cloud), `size_scale`,
`location`, `area`, `lc_min`, `size_sampling`. Thresholds are in SI units (N·m·s, m/s, m). Every case uses the
same seed (common random numbers), so differences between cases are the models'; results are identical
in-process and on Dask (tested).

The table (`--out`) has one row per case, metric and threshold, with `detectable_per_year`, `strikes_per_year`,
`area_m2`, `flux_m2_yr`, `on_array_fraction` and the case's parameters.

Library: `abrupt.rates.trades.Scenario`, `run_scenario`, `run_trade`; `abrupt.rates.montecarlo.RateConfig`,
`simulate_strikes`; `abrupt.rates.tables.nasa90_table`, `grun_table`, `read_flux_table`, `write_flux_table`;
`abrupt.rates.ordem.import_ordem`; `abrupt.rates.geometry.locate_strikes`, `silhouette_areas_m2`.

Method and sources
------------------

**Strike effects** (Bennett 2022 Eqs. 5.1-5.4): ΔP = β m V_d/s, ΔH = R_d/s × ΔP, ΔV = ΔP/m_sat, Δa = a(r,|v+ΔV|)
− a(r,|v|) with a = μr/(2μ − rv²) (evaluated in a cancellation-free form). Body frame = orbit frame (x radial, y
along-track, z orbit normal); circular orbit, so the thesis's random mean anomaly does not change anything in
this frame.

**Flux models** (`abrupt.rates.flux`, `abrupt.rates.tables`). All tables hold *cross-sectional* flux (impacts
per m² of area normal to the flow), the convention of ORDEM's spacecraft-mode output; the ECSS models give flux
on a randomly tumbling surface / single-sided randomly oriented plate, which is a quarter of that (Cauchy: mean
cross-section = surface/4), so the builders multiply by 4.

* *NASA-90/91 debris* (Kessler et al. 1991 as given in ECSS-E-10-04A/-ST-10-04C): F = k Φ(h,S) Ψ(i) [H(d) F1(d)
  g1(t) + F2(d) g2(t)], Φ = Φ1/(Φ1+1), Φ1 = 10^(h/200 − S/140 − 1.5), H(d) = √(10^exp(−(log10 d −
  0.78)²/0.637²)), F1 = 1.22e-5 d^−2.5, F2 = 8.1e10 (d+700)^−6, g1 = 1.02^(t−1988) (t < 2011) or 1.02^23 ·
  1.04^(t−2011), g2 = 1 + 0.05 (t−1988); d in cm, h in km (100 < h ≤ 2000 km), d ≥ 10 µm. The directions and
  speeds come from Kessler's crossing-orbit geometry: the spacecraft at a random argument of latitude meets
  circular debris orbits of a documented inclination mix (`DEFAULT_DEBRIS_INCLINATIONS`, an assumption [A]); the
  relative velocity is horizontal, 2v sin(Δψ/2), weighted by relative speed and the debris spatial density
  1/√(sin²i − sin²φ). Companion density law (mass model `nasa90_density`): ρ = 2.8 d^−0.74 g/cm³ above 0.62 cm,
  4 below.
* *Grün meteoroids* (Grün et al. 1985; ECSS-E-ST-10-04C §10.2.4.1 Eq. 101) at 1 AU, with Earth gravitational
  focusing per speed bin (Öpik/Liouville, the ECSS Annex C.1.2 procedure), Earth shielding sf = (1 + cos η)/2,
  sin η = (R_E + 100 km)/(R_E + h) (Eqs. C-13/C-14), and the spacecraft-motion factor K (C.1.3.2). The speed
  distribution is the NASA SSP 30425 one (11.1-72.2 km/s), taken as the distribution at 100 km (its lower bound
  is the escape speed there); meteoroid density 2.5 g/cm³; directions isotropic in the sky not blocked by the
  Earth, spacecraft velocity subtracted.

**Flux tables** (`abrupt-flux-table/1`, for ORDEM, MASTER or any other model): a TOML manifest

::

    format = "abrupt-flux-table/1"
    name = "ORDEM 3.1, 700 km, 98 deg, 2020"
    flux_convention = "cross_section"     # or "tumbling" (multiplied by 4 on load)
    altitude_km = 700.0                   # optional metadata; checked against the scenario
    inclination_deg = 98.0
    epoch_year = 2020.0
    size_table = "size.csv"
    direction_table = "direction.csv"

`size.csv`: `size_m,density_class,cumulative_flux_m2_yr,sigma_m2_yr` — cumulative flux of particles with
characteristic length ≥ size, per density class (`nak`, `low`, `medium`, `high`, `meteoroid`), with 1-σ; every
class on the same strictly increasing sizes; flux must not increase with size. `direction.csv`:
`speed_kms_lo,speed_kms_hi,azimuth_deg_lo,azimuth_deg_hi,elevation_deg_lo,elevation_deg_hi,flux_m2_yr` — bins of
relative speed and of the direction the particles come *from* in the orbit frame (azimuth from ram toward the
orbit normal, elevation from the local horizontal toward zenith), with relative weights. Size and direction are
drawn independently (the thesis's assumption). Each violation (empty table, header only, missing or unknown
column, non-numbers, negative or duplicated or out-of-order sizes, increasing cumulative flux, class grids that
differ, unknown class, speeds not in km/s, elevation outside ±90°, zero total) raises an error naming file,
line, column and reason. `--flux-bound ±2` shifts flux by ±2σ.

**ORDEM 3.x importer** (`abrupt rates import-ordem`): reads the size and igloo text tables by the words of their
header line (`size`, population words `nak`/`low`/`med`/`high`/`intact`, `total`, `sigma`/`upper`/`lower`; `az`,
`el`, `vel`/`speed`, `flux`), prints how it understood every column, and writes the documented format. Intacts
count as high density unless `--intact-class` says otherwise; 2-σ bounds become σ = (upper − lower)/4.

**Drawing**: inverse-transform sampling of the size table (power law within a bin) — the thesis's method
(`--size-sampling population`) — or, by default, **importance sampling**: Lc log-uniform over the table with
weights p/g (mean 1), so the rare millimetre particles that make detectable strikes are as well sampled as the
common 30 µm ones. The thesis noted that its curves were "choppy" with almost no ΔV-detectable draws for the
large craft in 10 000 draws; with importance weights 10 000-20 000 draws give smooth curves down to 10⁻⁵ of the
strike rate (test: importance and population estimates agree within 15 % where the population resolves them).

**Mass models** (`abrupt.rates.mass_models`): `al_sphere` (ρ 2800, erratum A16), `ordem_sphere` (class densities
0.9/1.4/2.8/7.9 g/cm³), `socit` (continuous reading ρ = 2.8 (L/0.79 mm)^−0.62, 7.9 (L/1.02 mm)^−1),
`socit_literal` (printed reading, 4.1 g/cm³ at 0.79 mm; erratum A12), `socit_no_steel`, `debrisat` (Eqs.
5.8-5.10, redrawn until ρ > 0; erratum A13), `nasa90_density`. **MEF** (`abrupt.rates.mef`):
`const1/2/3/const:x`, `nysmith_denardo`, `rembor`, `rembor_array` (β = 0.5 on arrays); fits floored at β = 1.

**Geometry** (`abrupt.rates.geometry`): boxes and two-sided panels from the spacecraft's `[[surfaces]]`;
solar-array panels rotate about their `u_axis` by an angle ~ U(0, π/2) per draw; CoM at the bus centre. Strike
location:
* `silhouette` (the thesis's; the library's :class:`~abrupt.rates.montecarlo.RateConfig` default, for the thesis
  reproductions): uniform point in the bounding rectangle of the projected geometry on the thesis's Q-R
  plane, ray cast along the flow, first surface hit kept, misses rejected — exactly uniform over the silhouette
  and forward-most, the thesis algorithm at zero grid spacing (numba);
* `point_cloud` (thesis): face and panel grid points (spacing ≤ 0.7 × grid), projected, rasterised at the grid
  spacing (default 1/6 of the smallest dimension), Q-slice by cell count, uniform R-cell, forward-most point.
* `visible` (the default of `abrupt rates`, with `--area silhouette`; the flux inference's forward model): a
  surface element facing the flow drawn ∝ its projected area, a point on it, a ray toward the source; the draw
  carries the facing area when unshadowed, 0 when shadowed, so strikes follow flux × visible area per direction. The two
  methods above draw the direction by flux alone: their total rate is right but a direction from which the craft
  looks large gets no more strikes than one from which it looks small (docs/flux-inference.md, *Strikes weighted
  by flux × visible area*; `tests/test_flux_visible_area.py`).

Effective area: `--area thesis` (Eqs. 5.15-5.18 with the total array area, erratum A14) or `--area silhouette`
(flux-weighted mean projected area, from ray casting); `abrupt rates` takes silhouette with the visible placement
and thesis with the thesis's placements unless `--area` is given.

Checks against the sources (tests in `tests/test_rates_*.py`)
-------------------------------------------------------------

* Nysmith-Denardo β at 10 / 68 km/s: Source value: 2.29 / 10.6; abrupt: 2.286 / 10.6
* Rembor β at 10 / 68 km/s: Source value: 3.4 / 20.8; abrupt: 3.4 / 20.8
* Table 2.2, both cases (ΔH = 80 mN·m·s; MLI 1.53, CFRP 0.75, Mylar 5.59 cm; Al 1.37, steel 0.95 mm, Cu wire
  1.29 cm, CFRP 1.42 mm, Mylar 1.07 cm): Source value: as printed; abrupt: all rows within rounding
* Figure 3.1 table, 12 rows × (ΔV, Al, steel, MLI, CFRP, Cu wire): Source value: as printed; abrupt: all within
  ±0.006 cm
* NASA-90/91, d ≥ 1 cm, 500 km, 28.5°, 1995, S = 100 (tumbling): Source value: "of order 1e-5 /m²/yr"; abrupt:
  1.142e-5 (Φ = 0.659, Ψ = 0.91, H = 1.293, g1 = 1.149, g2 = 1.35)
* NASA-90/91 at 4 other (d, h, i, t, S): Source value: term-by-term evaluation with `math`; abrupt: equal to
  1e-12
* Grün at 1 AU, m ≥ 1e-12 / 1e-9 / 1e-6 / 1e-3 / 1 g: Source value: Eq. 101 term by term; abrupt: 1088 / 95.06 /
  1.488 / 5.97e-4 / 7.0e-8 m⁻²yr⁻¹
* ECSS shielding at 400 km: Source value: (1 + cos η)/2, sin η = 6478/6778; abrupt: 0.647
* Focusing at 400 km: Source value: ECSS-E-10-04A mean-speed factor 1 + R/r = 1.94; abrupt: 2.07 (per-speed
  form; within 10 %)
* Debris relative speed, 30° / polar: Source value: Kessler 1988: ≈ 9 km/s / ≈ 13 km/s; abrupt: 10.1 / 12.5 km/s
* Debris mean impact speed, 28.5° / 98°: Source value: ECSS-E-ST-10-04C J.2.2.1.3: 10 / 13 km/s; abrupt: 10.1 / 13.1
  km/s
* SSP 30425 speed law at its joins, 16.3 / 55 km/s: Source value: the printed pieces meet within their digits;
  abrupt: 0.112 vs 0.11197, 1.695e-4 vs 1.693e-4 (allowed 1.9 % / 2.0 %); lower bound 11.1 km/s = v_esc at 100 km
  (11.09)
* Strike points for a bus alone: Source value: uniform over the silhouette, faces ∝ area·|n·d|; abrupt: χ² p >
  1e-3 for 5 random directions; KS uniform along axis views
* Silhouette area of a 1 × 2 × 3 m box: Source value: Σ |d·n| A; abrupt: within 3 % for 50 directions
* Doubling the area: Source value: doubles every rate; abrupt: exact (ΔV at every threshold; ΔH with the √2
  lever arm accounted)
* Δa for 2.4 cm/s along-track at 800 km: Source value: Gauss equation: ≈ 46 m; abrupt: 46 m

The Grün flux for m ≥ 1e-6 g is 1.49 m⁻² yr⁻¹ (4.7e-8 m⁻² s⁻¹) at 1 AU, computed from Eq. 101 itself
(F1 = 47.1^−4.38 = 4.7e-8 s⁻¹ dominates); the NASA-90/91 value above is of order 1e-5, as published.
Checked against the publications' text (tests/test_rates_published.py): Grün's F1-F3 coefficients as
ECSS-E-ST-10-04C §10.2.4.1 Eq. 101 prints them; R_E = 6378 km, the 100 km atmosphere (Annex C.1.3) and μ (Eq.
C-4). No ECSS table is used: the meteoroid speeds are SSP 30425's (not Table C-1's, which is Taylor's re-evaluation
of Harvard Radio Meteor Project data, C.1.1) and G, sf and K are computed by the Annex C.1.2/C.1.3 procedure (Eqs.
C-1 to C-11, C-13, C-14; not read from Table J-6); neither table's body could be read. Corroborated only by
secondary sources (public implementations of NASA-90/91 and a design note): the NASA-90/91 constants (1.22e-5
d^-2.5, 8.1e10 (d+700)^-6, H(d) 0.78/0.637, with H in the SPENVIS form 0.406 = 0.637², Φ, p, q, q'). Checked only
for consistency: the SSP 30425 speed law (its pieces join; its start is the escape speed at 100 km) and the debris
directions (mean speeds as ECSS J.2.2.1.3 and Kessler 1988 state them). Not checked against its publication: Ψ(i),
the NASA-90/91 inclination table (Kessler et al. 1991; NASA TM-100471 and TM-4527; ECSS-E-10-04A), of which no
readable copy was found (the sources tried are named in :mod:`abrupt.rates.flux`). abrupt uses the table as
recalled from its reproductions (no whole copy could be read; 30°, 80°, 90° and 120° rest on that recollection
alone): 28.5°: 0.91, 30°: 0.92, 40°: 0.96, 50°: 1.02, 60°: 1.09, 70°: 1.26, 80°: 1.71, 90°: 1.37, 100°: 1.78,
120°: 1.18. A public
design note that copies the model from SPENVIS prints 28.5°, 50° and 100° as here, 60° and 70° within 0.06,
and a monotone 1.4 and 1.6 at 80° and 90°; at the sun-synchronous 98° the readings differ by 2.6 %.
Ψ(45°) = 0.990 and Ψ(52°) = 1.030 quoted by two implementations agree. The inclination mix behind the debris
directions implies (:func:`~abrupt.rates.tables.debris_crossing_rate`, relative to 28.5°) values within 0.025 of the
table at 30-70° and 1.61 / 1.52 / 1.58 / 1.40 at 80° / 90° / 100° / 120°. Per-node evidence: the comment above
``PSI_VALUE`` in :mod:`abrupt.rates.flux`.

Limitations
-----------

* The analytic debris model is NASA-90/91, a 1991 model; it is valid to 2000 km, has no density classes and no
  uncertainty (use `--flux-sigma-factor` for an assumed one), and its velocity/direction model rests on an
  assumed inclination mix. For current environments use ORDEM or MASTER output through the table format. The
  ORDEM importer is keyed on header words and was tested on files written in the documented layout, not on real
  ORDEM output (none was available offline); check the column mapping it prints.
* Ψ(i) at 80° and 90° is read differently by the one readable secondary copy (see above); the 2.5 g/cm³
  meteoroid density is the one the Grün sizes are computed with, and the flux inference's default mass law for
  meteoroids uses the same value. The meteoroid speed distribution is SSP 30425's rather than ECSS Table C-1
  (not readable offline).
* Fluxes are orbit-averaged; no polar enhancement, no meteoroid streams, no seasonal variation. Size and
  direction are drawn independently unless a table gives them jointly (the format does not).
* Circular orbits only; body frame = orbit frame; arrays rotate about their drive axis only.
* Particles larger than the table's largest size are counted in the strike rate but never drawn (negligible for
  the analytic tables, which go to 1 m).
"""
