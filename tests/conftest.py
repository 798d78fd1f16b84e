"""Test configuration shared by the whole suite.

Hypothesis runs with random examples on developers' machines (that is how it
finds bugs: see the regression tests it left behind) and derandomised under CI
(``CI`` set), so that a submission's CI verdict does not depend on the luck of
one draw; the examples CI uses are still the same full budget per test.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")
