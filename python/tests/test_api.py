"""The Python API: the issue's contract, equality with the CLI's JSON, errors, in-memory inputs."""

from __future__ import annotations

import csv
import threading
from pathlib import Path
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import eigenfit


def test_contract_simulate_matches_cli(cli):
    r = eigenfit.simulate(model="paper-rotor", stiffness=[1e5, 1e5], modes=2)
    expected, code = cli(["simulate", "--preset", "paper-rotor", "--stiffness", "1e5,1e5", "--modes", "2"])
    assert r.to_dict() == expected
    assert code == 0 and r.exit_code == 0
    assert isinstance(r, eigenfit.SimulateResult)
    assert r.frequencies_hz.shape == (2,)
    np.testing.assert_array_equal(r.frequencies_hz, expected["frequencies_hz"])
    assert r.parameters == {"k_K1": 1e5, "k_K2": 1e5}
    assert set(r.sensitivities_hz) == {"k_K1", "k_K2"}


def test_contract_estimate_matches_cli(cli, examples):
    measured = examples / "measured_no_effect.csv"
    e = eigenfit.estimate(model="paper-rotor", measured=str(measured))
    expected, code = cli(["estimate", "--preset", "paper-rotor", "--measured", str(measured)])
    assert e.to_dict() == expected
    assert code == 0 and e.converged and e.acceptable
    assert set(e.parameter_status) == {"k_K1", "k_K2"}
    assert list(e.to_dict()["parameters"]) == ["k_K1", "k_K2"]
    assert e.parameter_values.shape == (2,)
    assert set(e.intervals) == {"k_K1", "k_K2"}
    for low, high in e.intervals.values():
        assert low < high
    assert e.identifiable == {"k_K1": True, "k_K2": True}
    np.testing.assert_array_equal(e.singular_values, expected["singular_values"])


def test_estimated_parameters_reproduce_the_fitted_frequencies(examples):
    """An identity across two calls: simulating at the estimate gives the estimate's frequencies."""
    e = eigenfit.estimate("paper-rotor", examples / "measured_no_effect.csv")
    n = len(e.frequencies_hz)
    r = eigenfit.simulate("paper-rotor", stiffness=e.parameter_values, modes=n)
    np.testing.assert_allclose(r.frequencies_hz, e.frequencies_hz, rtol=1e-12)


def test_model_file_path_matches_cli(cli, examples):
    path = examples / "rotor.toml"
    r = eigenfit.simulate(path, modes=3)  # a pathlib.Path
    expected, _ = cli(["simulate", "--model", str(path), "--modes", "3"])
    assert r.to_dict() == expected
    assert eigenfit.simulate(str(path), modes=3) == r


def test_sweep_matches_cli(cli):
    r = eigenfit.simulate("paper-rotor", modes=2, sweep=(1e4, 1e7, 4))
    expected, _ = cli(["simulate", "--preset", "paper-rotor", "--modes", "2", "--sweep", "1e4:1e7:4"])
    assert r.to_dict() == expected
    assert r.frequencies_hz is None
    assert r.sweep_frequencies_hz.shape == (4, 2)
    np.testing.assert_allclose(r.sweep_stiffness, np.logspace(4, 7, 4), rtol=1e-12)


def test_measured_mapping_equals_csv_file(examples):
    path = examples / "measured_no_effect.csv"
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    mapping = {
        "mode": np.array([int(r["mode"]) for r in rows]),
        "frequency_hz": np.array([float(r["frequency_hz"]) for r in rows]),
        "std_hz": [float(r["std_hz"]) for r in rows],
    }
    assert eigenfit.estimate("paper-rotor", mapping) == eigenfit.estimate("paper-rotor", path)


def test_measured_mapping_without_modes_counts_from_one(examples):
    freq = [30.2886, 97.8393, 306.4065, 580.6430]
    a = eigenfit.estimate("paper-rotor", {"frequency_hz": freq})
    b = eigenfit.estimate("paper-rotor", {"mode": [1, 2, 3, 4], "frequency_hz": freq})
    assert a == b and a.converged


def test_discover_matches_cli(cli, examples):
    measured = examples / "measured_hidden_effect.csv"
    d = eigenfit.discover("paper-rotor", measured)
    expected, _ = cli(["discover", "--preset", "paper-rotor", "--measured", str(measured)])
    assert d.to_dict() == expected
    assert d.disagreement_significant
    assert d.explained and d.exit_code == 0
    assert d.missing_effect["kind"] == expected["missing_effect"]["kind"]


def test_compare_matches_cli(cli):
    c = eigenfit.compare(
        "paper-rotor",
        targets=[(2e5, 5e4)],
        initials=[(1e5, 1e5), (1e6, 1e4)],
        strategies=["newton", "damped"],
    )
    expected, _ = cli(
        [
            "compare",
            "--preset",
            "paper-rotor",
            "--targets",
            "2e5:5e4",
            "--initials",
            "1e5:1e5,1e6:1e4",
            "--strategies",
            "newton,damped",
        ]
    )
    assert c.to_dict() == expected
    assert c.estimates.shape == (4, 2)
    assert c.converged.dtype == bool and len(c.converged) == 4


def test_not_converged_returns_the_result_with_exit_code_3(cli, examples):
    measured = examples / "measured_no_effect.csv"
    e = eigenfit.estimate("paper-rotor", measured, max_iterations=1)
    expected, code = cli(
        ["estimate", "--preset", "paper-rotor", "--measured", str(measured), "--max-iterations", "1"]
    )
    assert code == 3
    assert e.exit_code == eigenfit.EXIT_NOT_CONVERGED
    assert not e.converged and not e.acceptable
    assert e.verdict == expected["verdict"]
    assert e.to_dict() == expected


def test_to_dict_is_a_copy():
    r = eigenfit.simulate("paper-rotor", modes=2)
    d = r.to_dict()
    d["frequencies_hz"][0] = -1.0
    assert r.to_dict()["frequencies_hz"][0] > 0


@pytest.mark.parametrize(
    "call, fragment",
    [
        (lambda: eigenfit.simulate("no-such-rotor"), "no preset named `no-such-rotor`"),
        (lambda: eigenfit.simulate("paper-rotor", modes=0), "--modes 0"),
        (lambda: eigenfit.simulate("missing/rotor.toml"), "missing/rotor.toml"),
        (lambda: eigenfit.estimate("paper-rotor", "missing.csv"), "missing.csv"),
        (lambda: eigenfit.estimate("paper-rotor", {"frequency_hz": [30.0]}), "at least 2"),
        (
            lambda: eigenfit.estimate("paper-rotor", {"frequency_hz": [30.0, 90.0]}, strategy="guess"),
            "no strategy named `guess`",
        ),
    ],
)
def test_bad_input_raises_with_the_cli_message_and_exit_code_2(call, fragment):
    with pytest.raises(eigenfit.EigenfitError) as info:
        call()
    assert info.value.exit_code == 2
    assert fragment in info.value.message
    assert str(info.value) == info.value.message


def test_bad_measured_mapping_is_refused_before_the_call():
    with pytest.raises(ValueError, match="`std_hz` has 1 values"):
        eigenfit.estimate("paper-rotor", {"frequency_hz": [30.0, 90.0], "std_hz": [0.1]})
    with pytest.raises(ValueError, match="unknown keys"):
        eigenfit.estimate("paper-rotor", {"frequency": [30.0, 90.0]})
    with pytest.raises(TypeError, match="measured"):
        eigenfit.estimate("paper-rotor", [30.0, 90.0])


def test_concurrent_threads_get_their_own_results():
    """Each call's JSON is captured per thread: eight threads at once get exactly the serial results."""
    stiffnesses = [[10.0 ** (3 + i / 2), 10.0 ** (6 - i / 3)] for i in range(8)]
    serial = [eigenfit.simulate("paper-rotor", stiffness=k, modes=3) for k in stiffnesses]
    barrier = threading.Barrier(4)

    def call(i):
        if i < 4:  # the first four start together, so their commands overlap
            barrier.wait(timeout=60)
        return eigenfit.simulate("paper-rotor", stiffness=stiffnesses[i], modes=3)

    with ThreadPoolExecutor(max_workers=4) as pool:
        threaded = list(pool.map(call, range(len(stiffnesses))))
    assert threaded == serial
    assert len({tuple(r.frequencies_hz) for r in serial}) == len(stiffnesses)


def test_run_passes_arguments_through():
    r = eigenfit.run(
        ["simulate", "--preset", "uniform-rotor", "--elements", "8", "--modes", "2"], eigenfit.SimulateResult
    )
    assert r.model == "uniform-rotor" and r.frequencies_hz.shape == (2,)


class _FakeRossRotor:
    """Stands in for ross.Rotor (same module name, a save(path) method) to test the plumbing:
    the object is saved to a temporary file that the CLI reads, and errors say what it was."""

    __module__ = "ross.rotor_assembly"

    def __init__(self, text):
        self.text = text
        self.saved_to = None

    def save(self, path):
        self.saved_to = path
        path.write_text(self.text, encoding="utf-8")


def test_rotor_object_is_saved_to_a_temporary_file_the_cli_reads(examples):
    rotor = _FakeRossRotor((examples / "rotor.toml").read_text(encoding="utf-8"))
    r = eigenfit.simulate(rotor, modes=3)
    np.testing.assert_array_equal(
        r.frequencies_hz, eigenfit.simulate(examples / "rotor.toml", modes=3).frequencies_hz
    )
    assert rotor.saved_to is not None and not rotor.saved_to.exists()  # removed after the call


def test_unreadable_rotor_object_names_what_it_was():
    with pytest.raises(eigenfit.EigenfitError, match="the ROSS Rotor, saved with rotor.save()") as info:
        eigenfit.simulate(_FakeRossRotor("not a rotor ["), modes=2)
    assert info.value.exit_code == 2


def test_other_objects_are_refused():
    with pytest.raises(TypeError, match="preset name or a model file path"):
        eigenfit.simulate(42)


ROSS_DATA = Path(__file__).resolve().parents[2] / "crates/eigenfit-rotordynamics/tests/data"


def test_campbell_matches_cli(cli):
    rotor = ROSS_DATA / "rotor_example.toml"
    r = eigenfit.campbell(model=rotor, speeds=(0, 9000, 7), modes=4)
    expected, code = cli(["campbell", "--model", str(rotor), "--speeds", "0:9000:7", "--modes", "4"])
    assert r.to_dict() == expected
    assert code == 0 and r.exit_code == 0
    assert isinstance(r, eigenfit.CampbellResult)
    np.testing.assert_array_equal(r.speeds_rpm, np.linspace(0, 9000, 7))
    assert r.frequencies_hz.shape == (7, 4) and r.log_dec.shape == (7, 4)
    assert np.all(np.diff(r.frequencies_hz, axis=1) >= 0)  # ascending at each speed
    assert len(r.whirl) == 7 and all(w in ("forward", "backward", "mixed") for row in r.whirl for w in row)
    np.testing.assert_array_equal(r.critical_speeds_rpm, expected["critical_speeds_rpm"])
    # The string form of the speeds is the same call.
    assert eigenfit.campbell(model=str(rotor), speeds="0:9000:7", modes=4) == r
