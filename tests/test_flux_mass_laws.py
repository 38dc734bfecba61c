"""Each flux model's own size-to-mass law by default, stated in the result; identical spacecraft share a model."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from abrupt.catalog import Catalog
from abrupt.errors import ConfigError
from abrupt.flux.exposure import share_identical_models, spacecraft_model_digests, store_spacecraft_model
from abrupt.flux.forward import ForwardConfig, mass_law
from abrupt.rates import flux as fx
from abrupt.rates.mass_models import particle_mass_kg
from abrupt.rates.tables import grun_table
from doc_inputs import EXAMPLES


def test_default_meteoroid_masses_are_grun_masses() -> None:
    """Grün's flux is per mass; the table's sizes are spheres of 2.5 g/cm³, so the default law must give back
    exactly the masses the flux was tabulated at (aluminium's 2.8 g/cm³ would make them 12 % heavier)."""
    law = mass_law("grun", "meteoroid")
    table = grun_table(550e3)
    masses = particle_mass_kg(law, table.sizes_m, np.array(table.classes * table.sizes_m.size))
    np.testing.assert_allclose(masses, np.logspace(-15.0, np.log10(fx.GRUN_MAX_MASS_KG), table.sizes_m.size), rtol=1e-9)
    assert fx.METEOROID_DENSITY_KG_M3 == 2500.0


def test_default_debris_law_is_the_nasa90_density_law() -> None:
    """NASA-90/91's own law: 4 g/cm³ up to 0.62 cm, 2.8 d^-0.74 g/cm³ above (continuous at 0.62 cm)."""
    law = mass_law("nasa90", "debris")
    d = np.array([0.1e-2, 0.7e-2, 2e-2])  # [m]
    m = particle_mass_kg(law, d, np.array(["medium"] * 3))
    rho = m / (np.pi / 6 * d**3)
    np.testing.assert_allclose(rho, [4000.0, 2800.0 * 0.7**-0.74, 2800.0 * 2.0**-0.74], rtol=1e-9)
    assert 2800.0 * 0.62**-0.74 == pytest.approx(4000.0, rel=0.01)


def test_result_states_the_laws_and_a_chosen_law_applies_to_both() -> None:
    laws = ForwardConfig().describe()["mass_laws"]
    assert isinstance(laws, dict)
    assert laws["meteoroid"].startswith("ordem_sphere") and "2.5 g/cm³" in laws["meteoroid"]
    assert laws["debris"].startswith("nasa90_density")
    assert ForwardConfig(mass_model="socit").mass_laws() == {"debris": "socit", "meteoroid": "socit"}
    with pytest.raises(ConfigError, match="unknown mass model"):
        ForwardConfig(mass_model="lead")


def test_spacecraft_stored_under_several_names_share_one_model(tmp_path) -> None:
    cat = Catalog(str(tmp_path / "c.sqlite"))
    for name in ("SC-A", "SC-B", "SC-C"):
        store_spacecraft_model(cat, name, EXAMPLES / "fermi_like.toml")
    store_spacecraft_model(cat, "SC-D", EXAMPLES / "smallsat200.toml")
    exp = pd.DataFrame({"spacecraft_file": ["SC-C", "SC-B", "SC-A", "SC-D", "path.toml"]})
    shared = share_identical_models(exp, spacecraft_model_digests(cat))
    assert shared["spacecraft_file"].tolist() == ["SC-A", "SC-A", "SC-A", "SC-D", "path.toml"]
