"""The local-vs-Ray comparison (primitives.research.compare_backends): its two-proportion statistics."""

from __future__ import annotations

import pytest

from primitives.research.compare_backends import Proportions


def test_two_proportion_tests_agree_with_the_chi_square_test():
    from scipy.stats import chi2_contingency

    table = Proportions(successes=(260, 239), trials=(600, 600))
    z, p = table.z_test()
    chi2, p_chi2, _, _ = chi2_contingency([[260, 340], [239, 361]], correction=False)
    assert z > 0 and z**2 == pytest.approx(chi2) and p == pytest.approx(p_chi2)
    assert Proportions((239, 260), (600, 600)).z_test()[0] == pytest.approx(-z)
    assert 0.0 < table.fisher() <= 1.0
    assert Proportions((0, 0), (50, 70)).z_test() == (0.0, 1.0)  # nothing to tell apart


def test_rates_and_the_report_of_the_two_backends():
    table = Proportions(successes=(30, 45), trials=(100, 90))
    assert table.rates == (0.3, 0.5)
    d = table.as_dict()
    assert d["local"] == dict(successes=30, trials=100, rate=0.3)
    assert d["ray"] == dict(successes=45, trials=90, rate=0.5)
    assert d["z"] == pytest.approx(table.z_test()[0]) and d["z"] < 0  # local below ray
    assert d["p_z_test"] < 0.01 and d["p_fisher"] < 0.01  # 30 % against 50 %: told apart
    same = Proportions((50, 50), (100, 100))
    assert same.z_test() == (0.0, 1.0) and same.fisher() == pytest.approx(1.0)
    assert Proportions((0, 0), (0, 0)).rates == (0.0, 0.0)  # no trials yet: no division by zero
