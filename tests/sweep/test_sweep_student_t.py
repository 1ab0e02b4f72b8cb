"""restitution.sweep.student_t.t975 against scipy.special.stdtrit (the reference), over every regime it has:
the exact forms (1, 2), Newton on the incomplete beta (3 to 999), the expansion (1,000 up), non-integer
degrees of freedom, and NaN below 1. 1e-13 relative: the quantile is computed to a few ulps, and the
interval it scales needs far less."""
import math

import numpy as np
import pytest
from scipy.special import stdtrit

from restitution.sweep.statistics import _student_t975
from restitution.sweep.student_t import EXPANSION_FROM, t975

DOFS = [1, 2, 3, 4, 5, 7, 10, 19, 30, 99, 100, 399, 998, 999, EXPANSION_FROM, 1001, 5000, 10**5, 10**7, 1.5, 2.5, 3.7, 250.25]


@pytest.mark.parametrize("dof", DOFS)
def test_t975_is_scipys(dof):
    assert t975(dof) == pytest.approx(float(stdtrit(dof, 0.975)), rel=1e-13)


def test_below_one_degree_of_freedom_is_nan_and_arrays_map_each_value():
    assert math.isnan(t975(0)) and math.isnan(t975(0.5)) and math.isnan(t975(float("nan")))
    dof = np.array([[4.0, 0.0], [4.0, 1e6]])
    got = _student_t975(dof)
    assert got.shape == dof.shape and math.isnan(got[0, 1])
    np.testing.assert_allclose(got[[0, 1, 1], [0, 0, 1]], stdtrit(dof[[0, 1, 1], [0, 0, 1]], 0.975), rtol=1e-13)
