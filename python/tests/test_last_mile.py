"""Issue 33 from Python: mode shapes and the covariance as NumPy arrays, units by parameter, and a
misspelled keyword raised as Python's own TypeError naming it (not the CLI's usage text)."""

from __future__ import annotations

import numpy as np
import pytest

import eigenfit


def test_a_misspelled_keyword_is_a_type_error_naming_it_and_the_one_meant():
    with pytest.raises(TypeError) as e:
        eigenfit.simulate("paper-rotor", stifness=[1e5, 1e5])
    message = str(e.value)
    assert message.startswith("simulate() got an unexpected keyword argument 'stifness'; did you mean 'stiffness'?")
    assert "Usage" not in message and "modes" in message
    with pytest.raises(TypeError, match=r"estimate\(\) got an unexpected keyword argument 'max_iteration'; "
                                        r"did you mean 'max_iterations'\?"):
        eigenfit.estimate("paper-rotor", {"frequency_hz": [36.1, 84.1]}, max_iteration=5)
    with pytest.raises(TypeError, match=r"bench\(\) got an unexpected keyword argument 'strategy'; "
                                        r"did you mean 'strategies'\?"):
        eigenfit.bench(["paper-table3"], strategy="damped")
    # A keyword nothing resembles is named with the list of keywords, before anything runs.
    with pytest.raises(TypeError, match=r"argument 'no_such_option' Its keywords are: .*modes"):
        eigenfit.simulate("paper-rotor", no_such_option=1)


def test_simulate_shapes_are_an_array_of_dofs_by_modes_equal_to_the_cli(cli):
    r = eigenfit.simulate("paper-rotor", modes=3, shapes=True)
    expected, code = cli(["simulate", "--preset", "paper-rotor", "--modes", "3", "--shapes"])
    assert code == 0 and r.to_dict() == expected
    shapes = expected["mode_shapes"]
    assert r.mode_shapes.shape == (len(shapes["dofs"]), 3)
    for k in range(3):
        np.testing.assert_array_equal(r.mode_shapes[:, k], shapes["shapes"][k])
    assert r.dof_labels == shapes["dofs"] and r.dof_labels[:2] == ["v0", "theta0"]
    assert r.units == {"k_K1": "N/m", "k_K2": "N/m"}
    plain = eigenfit.simulate("paper-rotor", modes=3)
    assert plain.mode_shapes is None and plain.dof_labels is None


def test_estimate_covariance_and_correlation_are_arrays_in_the_parameters_order(examples):
    e = eigenfit.estimate("paper-rotor", examples / "measured_no_effect.csv")
    assert e.units == {"k_K1": "N/m", "k_K2": "N/m"}
    assert e["covariance"]["coordinates"] == "physical"
    assert e["covariance"]["parameters"] == list(e.parameters)
    c, r = e.covariance, e.correlation
    assert c.shape == (2, 2) and r.shape == (2, 2)
    sd = np.array([e.standard_deviations[name] for name in e.parameters])
    np.testing.assert_allclose(np.sqrt(np.diag(c)), sd, rtol=1e-12)
    np.testing.assert_allclose(r, c / np.outer(sd, sd), rtol=1e-12)
    np.testing.assert_array_equal(np.diag(r), [1.0, 1.0])
    # Without std there is nothing to compute: None, as the JSON's null.
    no_std = eigenfit.estimate("paper-rotor", {"frequency_hz": [36.107, 84.066, 305.649]})
    assert no_std.covariance is None and no_std.correlation is None
