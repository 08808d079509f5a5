"""Notebook display (issue 33): ``_repr_html_`` renders the tables of the CLI's ``--report`` page
from the result's JSON — the same rows, the same numbers, every text escaped."""

from __future__ import annotations

from html.parser import HTMLParser
from pathlib import Path
from typing import Dict, List, Optional, Tuple

from eigenfit import BenchResult, DiscoverResult, EstimateResult, Result

Cell = Tuple[str, Optional[float]]


class _Tables(HTMLParser):
    """Every table's rows by class: each cell's text and its ``data-value``; the verdict word."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: Dict[str, List[List[Cell]]] = {}
        self.verdict: Optional[str] = None
        self._table: Optional[str] = None
        self._row: Optional[List[Cell]] = None
        self._cell: Optional[List[str]] = None
        self._value: Optional[float] = None
        self._in_word = False

    def handle_starttag(self, tag: str, attrs: List[Tuple[str, Optional[str]]]) -> None:
        a = dict(attrs)
        if tag == "table":
            self._table = a.get("class") or ""
            self.tables[self._table] = []
        elif tag == "tr" and self._table is not None:
            self._row = []
        elif tag == "td" and self._row is not None:
            self._cell = []
            self._value = float(a["data-value"]) if a.get("data-value") else None
        elif tag == "span" and a.get("class") == "word":
            self._in_word = True

    def handle_endtag(self, tag: str) -> None:
        if tag == "td" and self._cell is not None and self._row is not None:
            self._row.append(("".join(self._cell), self._value))
            self._cell = None
        elif tag == "tr" and self._row is not None and self._table is not None:
            if self._row:
                self.tables[self._table].append(self._row)
            self._row = None
        elif tag == "table":
            self._table = None
        elif tag == "span":
            self._in_word = False

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)
        if self._in_word:
            self.verdict = (self.verdict or "") + data


def _parse(page: str) -> _Tables:
    p = _Tables()
    p.feed(page)
    return p


def test_an_estimate_shows_the_reports_tables(cli, examples: Path, tmp_path: Path) -> None:
    page = tmp_path / "report.html"
    data, code = cli(
        [
            "estimate",
            "--preset",
            "paper-rotor",
            "--measured",
            str(examples / "measured_no_effect.csv"),
            "--initial",
            "1e6,1e6",
            "--report",
            str(page),
        ]
    )
    result = EstimateResult(data, code)
    shown = _parse(result._repr_html_())
    report = _parse(page.read_text(encoding="utf-8"))
    assert shown.verdict == data["verdict"] == report.verdict
    # What the data determine, by rank (issue 29): in the JSON, the accessor, the notebook and
    # the CLI's page alike (two frequencies, two supports: full rank).
    rank = result.data_rank
    assert rank == data["data_rank"] and rank["rank"] == rank["parameters"] == 2
    said = f"determine {rank['rank']} of {rank['parameters']} parameter directions"
    assert said in result._repr_html_() and said in page.read_text(encoding="utf-8")
    params = shown.tables["parameters"]
    assert [row[0][0] for row in params] == list(data["parameters"])
    for row, (name, value) in zip(params, data["parameters"].items()):
        assert row[3][1] == value, name  # the exact estimate behind the shown digits
        assert row[4][1] == data["intervals"][name][0]
        assert row[5][1] == data["intervals"][name][1]
    # The same rows as the CLI's page: every cell's text and value, the unit column where the
    # JSON states units (else the page has them from the model's declaration).
    for table in ("parameters", "modes"):
        mine, theirs = shown.tables[table], report.tables[table]
        assert len(mine) == len(theirs), table
        for a, b in zip(mine, theirs):
            if table == "parameters" and "units" not in data:
                a, b = a[:1] + a[2:], b[:1] + b[2:]
            assert a == b, table


def test_a_discovery_shows_the_named_effect_and_the_parameters(cli, examples: Path) -> None:
    data, code = cli(
        ["discover", "--preset", "paper-rotor", "--measured", str(examples / "measured_hidden_effect.csv")]
    )
    shown = _parse(DiscoverResult(data, code)._repr_html_())
    assert shown.verdict == ("explained" if data["explained"] else "not explained")
    effect = data["missing_effect"]
    assert shown.tables["effects"][0][0][0] == f"{effect['kind']}@{effect['location']}"
    assert [(r[0][0], r[2][1]) for r in shown.tables["parameters"]] == list(
        data["calibrated_parameters"].items()
    )


def test_a_bench_shows_its_summary(cli) -> None:
    data, code = cli(
        ["bench", "--problems", "paper-table2", "--strategies", "newton,damped", "--starts", "2"]
    )
    rows = _parse(BenchResult(data, code)._repr_html_()).tables["summary"]
    assert [(r[1][0], r[3][1]) for r in rows] == [
        (s["strategy"], 100.0 * s["success_rate"]) for s in data["summary"]
    ]


def test_every_text_is_escaped() -> None:
    hostile = '<script>alert("x")</script>'
    r = EstimateResult(
        {
            "model": hostile,
            "verdict": hostile,
            "acceptable": False,
            "unique": True,
            "converged": False,
            "parameters": {hostile: 1.0},
            "initial": {hostile: 2.0},
            "parameter_status": {hostile: hostile},
            "measured_hz": [1.0],
            "frequencies_hz": [1.5],
        }
    )
    page = r._repr_html_()
    assert "<script" not in page
    assert page.count("&lt;script&gt;") >= 4
    shown = _parse(page)
    assert shown.verdict == hostile
    assert shown.tables["parameters"][0][0][0] == hostile
    # A field the class does not know still renders, escaped, through the base class.
    assert "<script" not in Result({"model": hostile, "note": hostile})._repr_html_()
