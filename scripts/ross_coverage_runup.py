"""The noise-free run-up behind the interval-coverage study of issue 16
(crates/eigenfit-rotordynamics/examples/runup_coverage.rs): ROSS's damped lateral whirl
frequencies of runup_nominal.toml (the rotor of the discovery run-ups, nothing hidden) at the
discovery speeds, 6 modes, std_hz 0.02 (the noise the study then draws; none is added here).

Run once, outside CI, in a virtual environment with ROSS (see scripts/ross_reference.py):

    /work/venvs/rotordyn/bin/python scripts/ross_coverage_runup.py

It writes crates/eigenfit-rotordynamics/tests/data/coverage_nominal.csv, with the helpers (mode
selection, whirl rule) of scripts/ross_realistic_runups.py.
"""

import importlib.util
import pathlib
import warnings

import ross as rs

warnings.filterwarnings("ignore")
HERE = pathlib.Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location("realistic", HERE / "ross_realistic_runups.py")
realistic = importlib.util.module_from_spec(spec)
spec.loader.exec_module(realistic)


def main():
    nominal = rs.Rotor.load(realistic.OUT / "runup_nominal.toml")
    realistic.write_runup("coverage_nominal.csv", nominal, realistic.DISCOVERY_SPEEDS, realistic.DISCOVERY_STD)


if __name__ == "__main__":
    main()
