"""eigenfit.MatricesModel: a sparse model from scipy.sparse matrices, checked against scipy."""

from __future__ import annotations

import numpy as np
import pytest

import eigenfit

sp = pytest.importorskip("scipy.sparse")
sla = pytest.importorskip("scipy.linalg")


def grid(nx: int, ny: int):
    """A membrane of nx×ny unit masses on springs, fixed all round; the springs of the left and
    right halves are the two zone matrices (K0 holds the ground springs at the border)."""
    n = nx * ny
    idx = np.arange(n).reshape(nx, ny)
    k0, zones = sp.lil_matrix((n, n)), [sp.lil_matrix((n, n)), sp.lil_matrix((n, n))]

    def spring(z, a, b, k):
        z[a, a] += k
        z[b, b] += k
        z[a, b] -= k
        z[b, a] -= k

    for i in range(nx):
        for j in range(ny):
            a = idx[i, j]
            zone = zones[0] if i < nx // 2 else zones[1]
            if i + 1 < nx:
                spring(zone, a, idx[i + 1, j], 1.0)
            if j + 1 < ny:
                spring(zone, a, idx[i, j + 1], 1.3)
            border = (i == 0) + (i == nx - 1) + (j == 0) + (j == ny - 1)
            k0[a, a] += 0.7 * border
    mass = sp.diags(1.0 + 0.05 * (np.arange(n) % 7))
    return k0.tocsr(), mass.tocsr(), [z.tocsr() for z in zones]


def lowest_hz(k, m, count):
    lam = sla.eigh(k.toarray(), m.toarray(), eigvals_only=True, subset_by_index=[0, count - 1])
    return np.sqrt(lam) / (2 * np.pi)


@pytest.fixture(scope="module")
def plate():
    k0, m, zones = grid(14, 11)
    params = [
        {"name": f"zone{i}", "nominal": 1.0, "lower": 0.1, "upper": 10.0, "scale": "log", "stiffness": z}
        for i, z in enumerate(zones, 1)
    ]
    return k0, m, zones, eigenfit.MatricesModel(k0, m, params, name="membrane")


def test_simulate_matches_scipy_dense_eigh(plate):
    k0, m, zones, model = plate
    r = eigenfit.simulate(model, modes=6, set={"zone2": 2.5})
    expected = lowest_hz(k0 + zones[0] + 2.5 * zones[1], m, 6)
    np.testing.assert_allclose(r.frequencies_hz, expected, rtol=1e-9)


def test_estimate_recovers_the_zone_factors_from_scipy_frequencies(plate):
    k0, m, zones, model = plate
    truth = [1.6, 0.7]
    measured = lowest_hz(k0 + truth[0] * zones[0] + truth[1] * zones[1], m, 6)
    e = eigenfit.estimate(model, {"frequency_hz": measured})
    assert e.converged
    np.testing.assert_allclose([e.parameters["zone1"], e.parameters["zone2"]], truth, rtol=1e-6)


def test_a_bad_parameter_is_refused_before_the_call():
    k0, m, zones = grid(4, 4)
    with pytest.raises(ValueError, match="nominal"):
        eigenfit.MatricesModel(k0, m, [{"name": "zone1", "stiffness": zones[0]}])
    with pytest.raises(ValueError, match="square"):
        eigenfit.MatricesModel(k0[:3], m)
