"""The bench from Python, and the one verdict's keys (issues 27 and 32) as Python users read them."""

import eigenfit


def test_bench_matches_cli(cli):
    r = eigenfit.bench(["paper-table3"], strategies=["damped", "trf"], starts=2, seed=1)
    expected, code = cli(
        ["bench", "--problems", "paper-table3", "--strategies", "damped,trf", "--starts", "2", "--seed", "1"]
    )
    assert r.to_dict() == expected
    assert r.exit_code == code
    assert len(r.records) == 4
    assert {s["strategy"] for s in r.summary} == {"damped", "trf"}
    for record in r.records:
        assert {"problem", "strategy", "start", "verdict", "evaluations", "final", "chi2", "reached_truth"} <= set(record)


def test_a_second_exact_solution_makes_the_estimate_not_unique(tmp_path):
    # Table 3 case 1's two frequencies: a second exact solution exists (docs/strategies.md).
    csv = tmp_path / "table3.csv"
    csv.write_text("mode,frequency_hz\n1,36.107\n2,84.066\n")
    e = eigenfit.estimate("paper-rotor", csv)
    assert e.exit_code == eigenfit.EXIT_NOT_CONVERGED
    assert e.acceptable and not e.unique
    assert e.to_dict()["verdict"] == "not-unique"
    assert e.termination_status == "converged"
    others = e.to_dict()["alternative_solutions"]
    assert any(a["equally_good"] and not a["mirror"] for a in others), others
