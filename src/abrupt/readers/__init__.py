r"""Readers: files into arrays and typed series, every repair counted, every error naming file, line
and column (docs/formats.md).

Orbits → `Ephemeris`
--------------------

SP3-a/b/c/d (`abrupt.readers.sp3`)
----------------------------------

Standards: Remondi 1989 (SP3-a), Hilla 2002 "The Extended Standard Product 3 Orbit Format (SP3-c)", Hilla 2016
"SP3-d" (IGS). Multi-satellite files: `read_sp3(path, "G01")`, `read_sp3_all(path)`; SP3-a ids such as `  1` are
read as `G01`.

* epochs: how: `*` records in the file's time system (GPS, GAL, QZS, IRN, BDT, GLO, TAI, UTC) → UTC: fixed
  GNSS−TAI offsets of the interface documents, then astropy's leap-second table
* positions, velocities: how: `P` km → m, `V` dm/s → m/s; clocks, accuracy exponents, `EP`/`EV` correlation
  records not used
* frame: how: the coordinate-system field: GCRF/ICRF/J2000/EME2000 → GCRF, anything else (IGS14, ITRF, SLR08,
  UNDEF…) → ITRF

Repairs (counted): epoch lines at a rollover value — minute 60 (`16 60` = 17:00), hour 24, second 60, day 0
(`2022 1 0` = 31 December) — normalised; where a producer had already advanced the day (`7 7 24 0` after `7 6 23
58`), the reading nearest the previous epoch plus the header interval is taken. Missing-value markers
(`0.000000`, `999999.999999`) remove that epoch for that satellite (velocity: NaN, see below). Identical
repeated epochs dropped; epochs sorted; gaps against the header interval counted. Records of a satellite absent
from the header list read and counted. Non-ASCII bytes in `/*` comments accepted. Epochs outside the leap-second
table (e.g. a long-term prediction in GPS time beyond the table's validity) are converted with TAI−UTC held at
its last tabulated value, and counted (also for OEM).

Per-epoch structure and physical consistency (`abrupt.readers.sp3_checks`), each counted under the name given:

* two `P` (or two `V`) records of one satellite in one epoch (swapped or duplicated lines): outcome: that epoch
  removed for the satellite (which record belongs to it cannot be told); counter: `two P or two V records of a
  satellite in one epoch (epoch removed)`
* a `V` record with no `P` record of its satellite before it in the epoch: outcome: dropped; counter: `velocity
  record without its position record (dropped)`
* a satellite with velocities at most epochs: an epoch whose velocity is missing, unreadable (`inf`, a malformed
  number: also counted as a malformed record) or the bad-value marker: outcome: epoch removed (a position alone
  is filtered with another noise model and can look like a velocity change); counter: `epoch without a usable
  velocity in a file with velocities (epoch removed)`
* the velocity is the derivative of the position: the central difference of the neighbouring positions against
  the velocity, on the epochs where the difference's truncation bound (Keplerian jerk, plus the Earth-rotation
  terms, × h²/6) is under 1 % of the speed; the median ratio must lie in [0.8, 1.25]: outcome: a ratio within 2
  % of 10, 100 (velocities in m/s or cm/s where dm/s is due, as in the GRG DORIS products of Jason-2 2008 and
  TOPEX 1997), with 90 % of the epochs within 5 % of it: the velocities are rescaled; any other ratio (a halved
  velocity gives 2, a sign flip −1): **error** naming the satellite and the ratio. The real files read give
  0.9993–0.9995, the chord-to-arc factor 1 − (n h)²/6; counter: `velocities off by a power of ten, positions
  intact (rescaled by 1e+1)` (every epoch counted)
* one epoch's derivative against its velocity, on the same epochs: more than 5 % of the speed apart (a position
  or velocity put at another epoch's place): outcome: that epoch and its two neighbours removed (a misplaced
  position spoils the differences on both sides); counter: `epoch whose position or velocity disagrees with its
  neighbours (removed with them)`

Errors: unsupported version (`#z`), malformed header lines (first line, `##`, `+` list, `%c`, `%f`, unknown
header record such as `@@`), more satellites than the version allows (85 for a/b/c), unknown time system, an
epoch off the header's sampling grid, an epoch repeated with different states, positions that are not an orbit
radius in km (a file in metres). **The header counts are checked against the body.** When the records are
complete — the file ends with `EOF`, or (holding more epochs than announced) its last epoch has a full set of
records and a whole last line — a mismatch is a counted repair that names both counts, and the file is read as
found: `header announces 5041 epochs, the file holds 5040 complete ones (read as found): 1` (the count is the
difference), `header announces 27 satellites but lists 26 (the list is used)`. This is how real ILRS files with
an off-by-one epoch count are read. `strict=True` (`--strict` on the orbit commands) keeps Orekit's behaviour:
any mismatch is an error (`file:line: header announces 192 epochs but the file holds 2`). A file without `EOF`
that holds fewer epochs than announced is a cut file, an error whatever the options (`header announces 13109
epochs but the file holds 6000 (truncated file?)`); `read_sp3(..., allow_truncated=True)` (`--allow-truncated`)
reads it and counts the missing epochs.

Orekit's 54 SP3 test files (`tests/test_sp3_corpus.py`) are each read or rejected as Orekit's `SP3ParserTest`
expects, with three documented differences: `wrong-number-of-epochs.sp3` (192 announced, 2 complete epochs,
`EOF`) is read with the counted repair above (an error with `strict=True`); files Orekit rejects only because an
accuracy base or the comment lines break the standard's limits (`wrong-*-base-*`, `too-*-comment*`) are read,
since abrupt uses neither; `gbm19500_wrong_data_used.sp3` is rejected, as by Orekit, but because an SP3-c file
cannot list its 87 satellites.

Writer: `write_sp3(ephemerides, path, time_system="GPS", version="d")` (1 mm, 10⁻⁷ m/s, 10 ns resolution);
property-tested round trip.

CCSDS OEM (KVN and XML) and OPM (`abrupt.readers.oem`)
------------------------------------------------------

Standard: CCSDS 502.0-B-3 "Orbit Data Messages" (2023) and the NDM/XML schema (CCSDS 505.0-B-2), which NASA uses
for ISS trajectory files (`<oem>`, also inside `<ndm>`, with `<segment><metadata>…<data>
<stateVector><EPOCH>…`).

- Epochs: calendar (`2023-02-15T12:00:00.000Z`) or day-of-year (`2023-046T12:00:00.000Z`), in `TIME_SYSTEM` UTC,
  TAI, GPS or TT → UTC (astropy).
- `REF_FRAME`: GCRF, ICRF, EME2000/J2000 (→ GCRF; the 23 mas frame bias is noted in the repair log), ITRF
  realisations (→ ITRF). `CENTER_NAME` must be EARTH.
- Several segments are concatenated (boundaries that repeat an epoch are dropped, counted); the object is chosen
  by `OBJECT_NAME` or `OBJECT_ID`.
- Covariance blocks (`COVARIANCE_START…STOP`, `<covarianceMatrix>`) are skipped and counted; accelerations
  ignored.
- Errors name the line and column (for XML, of the element): malformed XML (expat's message), missing metadata
  keywords, unknown frame/time system/centre, unreadable epochs or values, an unclosed block.

OPM (KVN): the state vector (one epoch) of an Orbit Parameter Message, units in brackets allowed. Writer:
`write_oem(eph, path, form="kvn"|"xml", time_system="UTC")` (1 µm, 10⁻⁹ m/s, 1 µs); round trip property-tested.

ILRS CPF (`abrupt.readers.cpf`)
-------------------------------

Standard: ILRS Consolidated Prediction Format v1.01 (2006) and v2.00 (2018). `H1` (format, version, target),
`H2` (ids, span, step, reference frame: 0 ITRF, 2 J2000 → GCRF; 1 true-of-date is refused), `10` positions (MJD,
seconds of day UTC, m), `20` velocities (m/s; an all-zero record means "not given"), `99` end. A file without
`99` is truncated: an error, or with `allow_truncated=True` a counted repair. Orekit's `cpf_*` test files are
read or rejected as its `CPFParserTest` expects (`tests/test_orbit_formats.py`).

Navigation CSV (`abrupt.readers.navigation_csv`)
------------------------------------------------

`time_utc,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps[,satellite][,frame]`, UTF-8, ISO-8601 UTC times. Errors name the row
and column.

The orbit envelope (`abrupt.readers.orbit_envelope`), every format
------------------------------------------------------------------

`read_ephemeris` (and every satellite of `detect orbit --all-satellites`) hands analysis only an Earth orbit.
Each check names itself in the error (`L27: outside the orbit envelope (speed below escape): …`):

* epochs not in the future: none later than today + 60 days (orbit predictions reach weeks ahead): outcome:
  **error** naming the epoch and the days; counter: —
* radius above the WGS-84 surface at the epoch's latitude and below the Moon's mean distance (384 400 km):
  outcome: **error** naming the epoch and the radius; counter: —
* single-epoch position outlier: the degree-7 Lagrange interpolation of its 4 neighbours on each side misses it
  by more than 10 robust σ of the arc's residuals (and 5 cm), and without it every neighbour's residual falls
  back below that level (a burn or a step of all later records does not): outcome: that epoch removed (a 50 m
  step in one record, an epoch 1-10 km off); counter: `single-epoch position outlier (disagrees with both
  neighbours) removed`
* velocity = derivative of position (the SP3 check above, in m and m/s): OEM, OPM, CPF and navigation CSV too:
  outcome: all-zero velocities: **error**; one epoch's zero vector: that epoch removed; a power-of-ten ratio
  (OEM velocities in m/s: 10⁻³; CSV velocities in km/s: 10³): rescaled; another ratio: **error**; more than
  10 % of the epochs off by over 5 % of the speed (position columns swapped): **error**; counter:
  `velocities off by a power of ten, positions intact (rescaled by 1e+3)`, `epoch whose velocity disagrees with
  its neighbours' positions (removed with them)`, `epoch with a zero velocity vector in a file with velocities
  (removed)`
* speed below escape: v²/2 − μ/r < 0 with the inertial velocity (an Earth-fixed one plus ω × r): outcome:
  **error** (an SP3 scaled ×1.5); counter: —
* dynamics of the stated frame: the acceleration the states imply (central difference of the velocities, or
  second difference of the positions, over a half-span keeping (n h)²/6 under 0.2 %, corrected by the circular
  orbit's sinc factor) against two-body + J2, with the Coriolis and centrifugal terms when the frame is
  Earth-fixed; median misfit above 3 % of gravity: outcome: **error**, saying whether the other frame fits (ITRF
  data labelled J2000: 12-14 % in LEO, the right frame 0.01 %; the real DORIS files give 0.006 %); counter: —

Gaps the orbit filters do not bridge (longer than half a revolution) end one analysed arc and start another
(`abrupt.pipelines.orbit_blocks.data_arcs`): nothing is tested in the gap, and the run says so.

Laser ranging and stations
--------------------------

ILRS CRD v1/v2 (`abrupt.readers.crd`)
-------------------------------------

Standard: ILRS Consolidated Laser Ranging Data Format v1.01 (2009) and v2.01 (Ricklefs & Moore 2019); full rate
(`.frd`), normal points (`.npt`, `.v2C`), sampled engineering; several blocks `H1…H8` per file, concatenated
files (`H9` followed by `H1`), lower-case records.

* `time_utc`: from: `H4` start date + seconds of day of `10`/`11` (a time more than 12 h before the block start
  is the next day: midnight rollover)
* `range_m`: from: `c·(tof − delay)/2` for two-way ranges (range type 2), `c·(tof − delay)` one-way (1)
* `system_delay_s`: from: mean `40` calibration delay of the block's configuration when `H4` says the station
  delay is **not** yet applied (counted); 0 otherwise
* `epoch_event`: from: which instant the epoch is (1 bounce, 2 ground transmit, …) — for the light-time model
* `pressure_hpa`, `temperature_k`, `humidity_pct`: from: `20` records, linearly interpolated to each range (held
  constant outside their span) — inputs of the Mendes-Pavlis tropospheric delay
* `station`, `station_id`, `satellite`, `ilrs_id`, `data_type`, `wavelength_nm` (`C0`), `bin_rms_s` (`11`),
  `troposphere_applied`, `centre_of_mass_applied`: from: header records

Repairs (counted): noise returns (filter flag 1) skipped; blocks with no ranges, receive times only, or mixed
range types skipped; identical duplicated ranges dropped; records sorted. Errors: not a CRD (`H1 CPF …`),
unsupported version, missing or malformed `H2`-`H4`, invalid range type (e.g. 9), a data record before `H4`, a
file ending inside a block or without `H9` (truncated; `allow_truncated=True` reads it, counted), an **unknown
station** when the caller passes the stations it can model (`unknown station 'GRZL' (pad 7839); known: …`).
Orekit's CRD test files (`tests/test_tracking_formats.py`) are read or rejected as its `CRDParserTest` expects.

`abrupt detect tracking` recognises CRD, CCSDS TDM and `.aer` files by content
(`abrupt.readers.tracking.read_tracking`), and refuses ranges whose implied speed no Earth satellite has (a
range in the wrong unit; plausibility table below).

SINEX (`abrupt.readers.sinex`)
------------------------------

Standard: SINEX 2.02 (IERS 2006). `SITE/ID`, `SOLUTION/ESTIMATE` (`STAX/Y/Z` m, `VELX/Y/Z` m/y, reference epoch
`YY:DDD:SSSSS`), `SOLUTION/EPOCHS` (validity of each solution number), `SITE/ECCENTRICITY` (`UNE` or `XYZ`, m).
`station.position_at(t)` = r₀ + v·(t − t₀) of the solution valid at t; `station.eccentricity_at(t)`. Errors: no
`%=SNX` header, an unclosed block, malformed estimates, a station lacking a coordinate or not on the Earth's
surface, and `sinex_station(stations, "7941")` for a station the file does not hold (the message lists those it
does, "no station" for an empty solution, and says to give a SINEX file holding it with `--sinex FILE`). Real
files are read as they are: free-text blocks may hold accented names (the text is read as Latin-1; the parsed
fields are ASCII), and a day of year `000` (`00:000:00000`, `30:000:00000`) is an open end. `read_sinex()`
without a path reads the ILRS SLRF2014 station coordinates bundled with abrupt (`abrupt/data/ilrs/`, provenance
and licence beside the file).

TLE/3LE and OMM histories are read plain or compressed (`.gz`, `.Z`, recognised by content); an empty file or an
SP3 orbit given where elements are expected is a one-line error saying what the file is.

What is not read
----------------

SP3 clock values and accuracies; OEM accelerations and covariances (skipped, counted); CPF corrections (`30`),
transponder and lunar records; CRD angles (`30`), range supplements (`12`), calibration details (`41`, `42`) and
session statistics (`50`); SINEX covariance matrices. OEM/OPM in XML form of OPM, OCM and OMM are not read here
(OMM: see `docs/tle.md`).

Plausibility checks of other inputs, and outputs
------------------------------------------------

* TLE, OMM (`abrupt.readers.tle_checks`): check: revolution numbers between consecutive sets 0.25–30 days apart
  against the mean motion × elapsed time (±2 rev + 10 %); outcome: a history whose revolution numbers grow more
  than twice as fast as its mean motion allows, at most pairs, is an **error** (mean motion in rad/min,
  deg/min); other disagreeing pairs (restarted or unkept counts) are counted and kept; counter: `consecutive
  sets whose revolution numbers disagree with the mean motion (kept)`
* TLE, OMM: check: one set whose mean motion is more than twice or under half that of both neighbours, which
  agree within 10 %; outcome: **error** naming its line; counter: —
* `density tle` output (`abrupt.density.drag_plausibility`): check: an object whose largest possible drag decay
  at its lowest perigee (B = 100 m²/kg at the extreme NRLMSIS density, over a window's longest span) is below
  its own mean-motion noise; outcome: skipped before propagation, no windows, counted and printed; counter:
  `objects skipped: no drag signal above {n} km (perigee {n} km)`
* `density tle` output: check: a window whose K − 3σ_K exceeds 100 m²/kg × its model density; outcome: kept with
  `status = implausible ballistic coefficient`, counted and printed, not used by the order statistics; counter:
  `windows refused: implausible ballistic coefficient (K - 3 sigma above 100 m2/kg x model density)`
* telemetry archive (`abrupt.readers.archive`): check: values that are infinite or beyond 1e20 in magnitude
  (above any 64-bit counter); outcome: removed, counted per spacecraft-day in the ingest report; counter:
  `infinite or absurd values (|v| > 1e20)`
* every command (`abrupt.cli.commands`): check: every output option (`--out`, `--report`, `--statistics-out`,
  `--fit-out`, `--diagnostics-out`, `--truth`, `--setup-out`, `--json`, `--plot`, `--scatter`, `--write-table`,
  `--parts`) that is the same file as an input or the SQLite catalog (by path, or by device and inode: a hard
  link), a symbolic link, a device or pipe, or the same file as another output; a `--catalog` that is an input
  file; outcome: **error** before anything runs; counter: —
* every command with an output: check: an output that is an existing file; outcome: **error** before anything
  runs, unless `--overwrite`; counter: —
* every command with an output: check: an output inside the telemetry store the command reads (`store export`,
  `detect attitude --store`): a stored file, or a new file the store would then hold; outcome: **error** before
  anything runs, also with `--overwrite`; counter: —
* telemetry store (`abrupt.store`): check: a stored day's Parquet file that does not read (cut by a kill or a
  full disk), also when an ingest finds the same archive already stored; outcome: **error** naming the file;
  counter: —
* telemetry archive (`abrupt.readers.archive`): check: rows dated more than a day after today; a last line cut
  by an interrupted export (no line end, fields missing); a CSV that is not UTF-8; outcome: the rows removed and
  counted, the cut line skipped and counted, the non-UTF-8 file an **error** naming line and column; counter:
  `rows dated after today (telemetry is recorded, not predicted)`, `last line cut (no line end, fields missing:
  skipped)`
* attitude telemetry, `catalog import`: check: a time more than a day after today; a ΔV above 20 km/s (orbital
  plus escape speed); outcome: **error** naming line and column; counter: —
* TLE, OMM: check: |B*| above 10 per earth radius (ρ0·Cd·A/(2m) of the lightest debris is 6.9); outcome: the set
  skipped and named; counter: `malformed element sets skipped`
* Orekit set-up (`abrupt.readers.orekit_od_input`): check: an a-priori state with v²/2 − μ/r ≥ 0, a perigee
  inside the Earth or an apogee beyond the Moon (a velocity in km/s or ×1.5); outcome: **error** naming the line;
  counter: —
* density platforms, flux exposure table: check: max_area_m2/mass_kg above 100 m²/kg (an area in cm²); an
  altitude beyond the Moon's distance; outcome: **error** naming the line; counter: —
* every text reader (`abrupt.readers.compression.read_bytes`): a leading UTF-8 byte-order mark is dropped (it is
  no part of any format); outcome: read as without it; counter: —
* every output (`abrupt.outputs.atomic_output`): check: written beside the target under a hidden temporary name
  and renamed over it; a path a command derives (`OUT.json`, `OUT.injections.csv`) that is one of the command's
  inputs; a full disk or read-only folder; outcome: the previous file stays whole, no temporary file is left;
  the derived input path is an **error**; a full disk is a one-line **error** naming the output; counter: —
* `detect` commands (`abrupt.catalog`): check: the catalog is opened, created or upgraded and written to (one
  unchanged row) before the work; an in-memory `sqlite://` catalog; a malformed URL (a port that is not a
  number); outcome: a read-only or unusable catalog is an **error** before anything is read or written; the
  events file is renamed into place only after the catalog stored the run, so a catalog that fails leaves no
  events file; counter: —
* spacecraft TOML (`abrupt.model.spacecraft.check_mass_properties`): check: the radius of gyration √(I_max/m)
  against 2 × the radius enclosing the declared surfaces and appendages (30 m without geometry); the trace of
  the inertia against that of an osmium sphere of the same mass; mass above 1e6 kg; a direction (wheel, gimbal
  axis, panel normal) whose largest component is above 1 or below 1/√3; outcome: **error** naming
  `inertia_kgm2`, `mass_kg` or the axis key (an inertia in g·m² or kg·cm² is refused for every shipped
  spacecraft file); counter: —
* spacecraft TOML `[orbit]`, `[flight]` (`abrupt.model.flight_config`): check: `period_s` outside Kepler's
  bounds for an Earth orbit (5069 s at the surface to 2.37e6 s at the Moon); `altitude_km` beyond the Moon;
  `inclination_deg` above 180; `grid_hz` above 10 Hz or above the fastest attitude channel's `rate_hz`; outcome:
  **error** naming the key; counter: —
* attitude telemetry (`abrupt.readers.telemetry`): check: when the attitude moves well above noise, the gyro
  rates fitted by the rates implied by the quaternions read with the scalar first and with it last; outcome: the
  other order fitting with a factor within 0.8-1.25 and a third of the declared order's residual is an **error**
  naming the columns and the `order` to set; counter: —
* CSV inputs (telemetry, archives, navigation CSV; `abrupt.readers.text.check_column_count`): check: more than
  20 000 columns in the first line; outcome: **error** naming line 1, before parsing; counter: —
* OEM XML: check: a document type declaration (entity expansion); outcome: **error** naming its line; character
  data is joined once per element (linear time); counter: —
* `.aer`: check: at least 10 AZ_EL lines, all azimuths within 0-2π and elevations within ±π/2; outcome:
  **error**: radians, the format's unit is degrees; counter: —
* `detect tracking` (`abrupt.pipelines.tracking.check_span_from_epoch`): check: measurements more than 60 days
  from the set-up's a-priori epoch; outcome: **error** before any propagation; counter: —
* archive decoder (`abrupt.readers.archive.read_decoder`): check: a pseudonym that contains or equals a real
  name of the decoder (case-insensitive), or holds a control character; outcome: **error** naming the lines,
  never the names; counter: —
* TLE/OMM names, notes, warnings, `catalog list`: check: control characters (terminal escape sequences, the
  bell); outcome: written as visible escapes (`\x1b`); counter: —
* archive ingest with `--spacecraft FILE` (`abrupt.pipelines.flight_checks.physical_bounds`): check: a
  quaternion component beyond 1.1, a body rate beyond 2 rad/s, a wheel speed beyond 1.5 × its wheel's
  `max_speed_rad_s` (each in the channel's declared unit); outcome: removed, counted per day; counter: `values
  beyond the spacecraft file's physical bounds`
* archive ingest with `--spacecraft FILE` (`flight_checks.within_bounds`): check: most samples of one channel
  (more than half, at least 10, in one archive file) beyond that bound; outcome: **error** naming the archive,
  the channel and the spacecraft file: the channel's unit or the file's limit is wrong (values ×1000; a wheel
  limit ×0.1); counter: —
* archive ingest with `--spacecraft FILE` (`flight_checks.check_quaternion_norm`): check: the median over the
  file's epochs of |norm − 1| of the four `[flight]` quaternion channels above 0.01 (the real archive's: 2e-9);
  outcome: **error** naming the archive and the channels (a scaled quaternion channel); counter: —
* archive ingest with `--spacecraft FILE`: check: a spacecraft file without a `[flight]` table (e.g. cut before
  it); outcome: **error** naming the file and the table; counter: —
* spacecraft TOML (`abrupt.model.spacecraft`): check: a wheel without `max_speed_rad_s`; outcome: its documented
  default (630 rad/s) is used, printed as a warning naming the wheel and kept in `Spacecraft.defaults`; counter:
  —
* `detect attitude`, `estimate inertia` on a store: check: the gyro against the quaternion's rate; an angle
  declared `rad` beyond 2π; the wheels against conservation and the tachometer quantum; outcome: **error**
  naming `flight.channels[k].unit` of the channel that disagrees (docs/flight-pipeline.md); counter: —
* events files (`abrupt.events.write_events`): check: written under a temporary name beside the target and
  renamed over it (a link at the target is replaced, not followed); outcome: —; counter: —
* `detect tracking`: `.aer`, TDM, CRD read on the set-up's stations
  (`abrupt.pipelines.tracking.read_tracking_arrays`, `abrupt.model.implied_orbit`): check: per station with
  ranges and angles: positions at the range epochs (angles interpolated linearly, range bias removed), chord
  velocities over the shortest baseline whose stated noise is 5 % of the circular speed (at most 1/12 of the
  circular period), each speed against vis-viva's bounds at its radius: the apogee speed of an orbit grazing the
  surface, √(2μR_E/(r(r+R_E))), and the escape speed √(2μ/r); outcome: the median ratio below the first or above
  the second by more than 3 standard errors of the median is an **error** naming the file, column `range` and
  the station (ranges ×0.1: 0.06-0.11 of the least speed; ×10: 13-20 times escape); stations with fewer than 3
  velocities are not judged; Earth-escape trajectories are refused; counter: —
* `detect tracking` (`abrupt.model.implied_orbit.check_ranges_against_orbit`): check: every station's ranges
  (bias removed; up to 200 spread over the file, after the set-up epoch) against those of the set-up's a-priori
  orbit (two-body): the fit starts from that orbit and linearises around it; outcome: a median ratio beyond a
  factor of two is an **error** naming the file, column `range` and the station: ranges in the wrong unit or an
  a-priori of another satellite (W3B's real ranges: within 0.11 % of the a-priori's over 15.8 h; a station
  without angles is judged only here); counter: —
* `catalog list --detector`: check: `%` and `_` are characters, not LIKE wildcards; outcome: —; counter: —
* TLE: check: a line longer than 160 characters (a TLE line has 69, a 3LE name 24); outcome: **error** naming
  its line, quoting 80 characters; counter: —
* Orekit set-up (`.in`): check: a byte that is not UTF-8; outcome: **error** `file:line:column` naming the byte;
  counter: —
* every reader (`abrupt.errors`): check: an error's reason is cut at 400 characters; the `.aer`, Orekit set-up
  and TLE readers quote at most 80 characters of a field or line; outcome: —; counter: —
* catalog (`abrupt.catalog.foreign`): check: a table named like one of abrupt's (`events`, `runs`, `coverage`,
  `tasks`) in a database without abrupt's `abrupt_schema` table and without abrupt's columns; outcome: **error**
  naming the table; the database is not changed (never migrated, dropped or filled); counter: —
* catalog: check: a text longer than its column (`String(200)`: spacecraft, detector, kind…); outcome: **error**
  on SQLite as on PostgreSQL, before the events file or a run row is written; counter: —
* archive ingest: check: real names of the decoder in file names and texts; outcome: replaced by their
  pseudonyms whatever their case; counter: —
* `abrupt score EVENTS --truth FILE --elements TLE`: check: the element sets' catalogue number against the
  events' spacecraft (`NORAD-n`, as `detect tle` names it); outcome: **error** naming both satellites; counter:
  —

The mutation suite
------------------

`tests/test_mutation_suite.py` (machinery in `tests/mutation_harness.py`) gives 19 kinds of damage to a small
slice of a real file for each of 18 readers (SP3, OEM in KVN and in XML, CPF, navigation CSV, CRD, TLE, OMM, TDM
and `.aer` (read as `detect tracking` reads them, on the stations of `od_test_W3.in`), Orekit set-up, SINEX, IDS
and Fengyun maneuver files, telemetry CSV and Parquet, archive ingest with `--spacecraft`, spacecraft TOML): a
cut in the middle of a record and at a record boundary, a digit flipped to a letter, a deleted, duplicated and
swapped line, NaN, inf and 1e300 in a value, a unit change ×0.1 and ×1000 of a physical column, an empty file, 4
kB of seeded garbage, a 2 MB line, a cut gzip stream, non-UTF-8 bytes, CRLF line ends, a directory and a file
without read permission. Each run must give abrupt's one-line error naming the file, a counted repair, the
unmutated rows, or (for a removed line or a cut at a record boundary in a format without a record count) a
subset of them, none altered; in under 60 s and with the process's peak memory rising by less than 1 GB (`-m
slow`: a 50 MB line and 5 MB of garbage in a child process, its own peak under 1 GB). What it found and what was
fixed:

* every reader: check: a file that exists but cannot be read (permissions, device error); outcome: **error**
  `file: cannot read file: Permission denied`
* IDS, Fengyun maneuvers: check: an empty file or one without a maneuver line; outcome: **error** (it was an
  empty table)
* IDS maneuvers: check: a burn duration, delta-v or acceleration that is not finite or beyond 10⁶; outcome:
  **error** naming the line
* IDS, Fengyun maneuvers: check: bytes that are not ASCII (IDS) or UTF-8 (Fengyun), a directory; outcome:
  **error** naming the line and column, or the file
* TLE, OMM: check: an element that reads as NaN or inf (checksum valid); outcome: **error** naming the line and
  column (a malformed set, skipped and counted in a long file)
* telemetry CSV/Parquet: check: a value that is infinite or beyond 10²⁰; outcome: row removed, counted (it
  overflowed in the quaternion norm)
* SINEX: check: a solution with one or two of `VELX/VELY/VELZ`; outcome: **error** (a velocity component was
  NaN)
* spacecraft TOML: check: a wheel's `max_speed_rad_s` above 2000 rad/s (≈ 19 000 rpm); outcome: **error** naming
  the key: check the unit
* archive ingest: check: bytes that are not UTF-8 in a text column; outcome: **error** naming the file (was a
  pyarrow traceback)

Damage no reader can tell from valid data is declared per reader in the suite (`beyond_reach`) and listed here;
no reader declares any today. Ranges ×0.1 in `.aer` and TDM files were declared until the implied-speed check
(plausibility table above): a range a tenth of the real one is still a possible range of some satellite above
the station, and the measurement file holds neither the station's position nor the orbit, so the reader alone
cannot tell. `detect tracking` has the stations (set-up file), and ranges with angles are positions, so it holds
the speed they imply against vis-viva: ranges ×0.1 of W3B imply 0.06-0.11 times the least orbital speed and are
refused naming the station; ranges without angles are held against the set-up's a-priori orbit. (The set-up's
a-priori state was once thought no bound because it moves at 1.66 km/s; W3B was in its transfer orbit, perigee 6
591 km from the Earth's centre, and the implied speeds of the real arc agree with that orbit's vis-viva speed
within 3 %, `tests/test_implied_orbit.py`.) In key = value files (Orekit set-up) a deleted optional line
likewise means its default.

The spacecraft TOML is judged on the path a user runs with it (ingest, given it with `--spacecraft`, of a real
archive slice): a cut between two tables that drops `[flight]` is refused (no bounds could be applied); a
deleted `max_speed_rad_s` takes its printed default; a wheel limit ×0.1 puts every wheel sample beyond 1.5 × the
limit and is refused. Archive values ×0.1 (every channel) are refused by the quaternion norm. A cut inside the
`[flight]` channel list (a valid, shorter list) and a tenth of one gyro or wheel channel are not seen at ingest
(each stays within its bound). `detect attitude` holds the gyro against the quaternion's rate axis by axis
(|ω_q|² = Σ s_i² g_i² fitted over the axes that carry at least 5 % of the gyro's squared rate) and names the
channel that is off: on the real archive the Y gyro channel a tenth too small is refused naming `SC-A.ch06`; an
axis that reads only noise (X and Z there) cannot show its scale. One wheel channel a tenth of its speed is
refused there too, naming that channel: its values no longer step in the declared tachometer quantum (0.9375
rpm).
"""
