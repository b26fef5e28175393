"""The paper's Table 1 and figures."""

import subprocess
import sys

import pytest

from beltsim.studies import paper

# Table 1 of Oborin & Vetyukov (2019), N: the published numbers
PUBLISHED = {"No inertia, no slip": (6482, 6237, 12719),
             "With inertia, no slip": (2024, 5375, 7398),
             "With inertia, with slip": (3253, 3870, 7124)}


@pytest.mark.unit
def test_table1_reproduces_the_published_numbers():
    for row in paper.table1():
        got = (round(row["concentrated_or_slipping"]), round(row["distributed_or_sticking"]),
               round(row["total"]))
        assert got == PUBLISHED[row["case"]]


@pytest.mark.unit
def test_format_table1_prints_whole_newtons():
    text = paper.format_table1(paper.table1())
    for numbers in PUBLISHED.values():
        assert all(str(n) in text for n in numbers)


@pytest.mark.cli
@pytest.mark.parametrize("with_sim", [False, True])
def test_paper_command_writes_table_and_figures(tmp_path, with_sim):
    args = [sys.executable, "-m", "beltsim.cli", "paper", "--out", str(tmp_path)]
    proc = subprocess.run(args + ([] if with_sim else ["--no-sim"]), capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "12719" in proc.stdout and "7124" in proc.stdout
    assert (tmp_path / "table1.csv").read_text().count("\n") == 4
    for k in range(2, 8):
        assert (tmp_path / f"fig{k}.png").stat().st_size > 20_000
    if with_sim:
        assert proc.stdout.count("steady after") == 6
