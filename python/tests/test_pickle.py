"""Pickling: results and errors survive a round trip (what Dask, Ray and multiprocessing do)."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import eigenfit


@pytest.fixture(scope="module")
def results(examples):
    return [
        eigenfit.simulate("paper-rotor", stiffness=[1e5, 1e5], modes=2),
        eigenfit.estimate("paper-rotor", examples / "measured_no_effect.csv"),
        eigenfit.estimate("paper-rotor", examples / "measured_no_effect.csv", max_iterations=1),
        eigenfit.discover("paper-rotor", examples / "measured_hidden_effect.csv"),
        eigenfit.compare("paper-rotor", targets=[(2e5, 5e4)], initials=[(1e5, 1e5)]),
        eigenfit.bench(["paper-table3"], strategies=["damped"], starts=1, seed=1),
    ]


@pytest.mark.parametrize("protocol", [2, pickle.HIGHEST_PROTOCOL])
def test_results_round_trip(results, protocol):
    for r in results:
        back = pickle.loads(pickle.dumps(r, protocol=protocol))
        assert type(back) is type(r)
        assert back == r
        assert back.to_dict() == r.to_dict()
        assert back.exit_code == r.exit_code


def test_round_trip_keeps_arrays_bit_for_bit(results):
    e = results[1]
    back = pickle.loads(pickle.dumps(e))
    np.testing.assert_array_equal(back.frequencies_hz, e.frequencies_hz)
    assert back.parameters == e.parameters


def test_copy_and_deepcopy(results):
    for r in results:
        assert copy.copy(r) == r and copy.deepcopy(r) == r


def test_error_round_trips():
    with pytest.raises(eigenfit.EigenfitError) as info:
        eigenfit.simulate("no-such-rotor")
    back = pickle.loads(pickle.dumps(info.value))
    assert (back.message, back.exit_code) == (info.value.message, info.value.exit_code)
