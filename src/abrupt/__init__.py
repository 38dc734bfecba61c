"""abrupt: find abrupt, unexpected momentum changes in satellite telemetry and tracking data.

Data flow: readers -> model -> detect -> thresholds -> events -> catalog -> report.
Simulators in :mod:`abrupt.simulate` feed the same path with known truth; :mod:`abrupt.rates`
predicts how many detectable events a spacecraft should see per year.
"""

__version__ = "0.1.0"

from abrupt.jit_cache import use_keyed_numba_cache

use_keyed_numba_cache(__version__)
