"""The command line's answers to the mistakes of a user: results folders that belong to
another study, output paths that cannot be written, study files read from another directory,
run names, and what --help and --version show. Each error is one line, exit code 2, before
any work."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from trackbench.cli.app import app
from trackbench.study import StudyError, load_study, store
from trackbench.study.execute.runner import check_output, manifest
from trackbench.study.spec.study_file import resolved_toml

CLI = [sys.executable, "-c", "from trackbench.cli import main; main()"]
FAST = "duration = 0.05\noutput_interval = 0.001\nrecord = { enabled = false }\n"


def invoke(args):
    r = CliRunner().invoke(app, args)
    return r.exit_code, r.output.strip()


def one_line_error(out):
    assert out.startswith("error: ") and "\n" not in out, out
    return out


def study_file(folder, fname, speeds, name="coll", extra=""):
    p = Path(folder) / fname
    p.write_text(f"[study]\nname = '{name}'\n{extra}[scenario]\n{FAST}[grid]\nspeed = {speeds}\n")
    return p


def fake_results(study, completed=()):
    """The folder `study run` leaves (study.toml, runs.json, run.json of ``completed``) without running."""
    store.write_text(study.output / "study.toml", resolved_toml(study))
    store.write_json(study.output / "runs.json", manifest(study))
    for r in study.runs[: len(completed)]:
        store.write_json(
            store.run_dir(study.output, r.run_id) / "run.json",
            {"run_id": r.run_id, "status": "completed", "results": {}},
        )
    (study.output / "summary.csv").write_text("kept\n")


def snapshot(folder):
    return {str(p.relative_to(folder)): p.read_bytes() for p in Path(folder).rglob("*") if p.is_file()}


# --- a results folder belongs to one study file ------------------------------------------


def test_a_study_of_the_same_name_from_another_file_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    a = load_study(study_file(tmp_path, "a.toml", "[5.0, 6.0]"))
    a.output = a.output.absolute()
    fake_results(a, completed=[0])
    before = snapshot(a.output)
    study_file(tmp_path, "b.toml", "[3.0, 4.0]")
    code, out = invoke(["study", "run", "b.toml"])
    assert code == 2
    msg = one_line_error(out)
    assert str(tmp_path / "a.toml") in msg and "b.toml" in msg and "results/coll" in msg
    assert "another [study] name" in msg and "--output" in msg
    assert snapshot(a.output) == before  # nothing replaced, nothing added
    # the same file, edited, still owns the folder; so does the same file reached by another path
    check_output(load_study(study_file(tmp_path, "a.toml", "[5.0, 6.0, 7.0]")))
    os.symlink(tmp_path / "a.toml", tmp_path / "link.toml")
    s = load_study(tmp_path / "link.toml")
    check_output(s)
    with pytest.raises(StudyError, match="holds the results of another study file"):
        check_output(load_study(tmp_path / "b.toml"))


def test_a_folder_without_a_recorded_source_is_matched_by_the_file_name(tmp_path, monkeypatch):
    """Folders written before runs.json recorded the source: study.toml's first line names the
    file as it was given (relative): the same file name resumes, another is refused."""
    monkeypatch.chdir(tmp_path)
    a = load_study(study_file(tmp_path, "a.toml", "[5.0]"))
    fake_results(a)
    m = json.loads((a.output / "runs.json").read_text())
    del m["source"]
    (a.output / "runs.json").write_text(json.dumps(m))
    assert (a.output / "study.toml").read_text().startswith("# resolved copy of ")
    check_output(load_study(tmp_path / "a.toml"))
    with pytest.raises(StudyError, match="another study file, .*a.toml; running .*b.toml there"):
        check_output(load_study(study_file(tmp_path, "b.toml", "[5.0]")))


def test_run_python_api_refuses_too(tmp_path, monkeypatch):
    from trackbench.study import run_study

    monkeypatch.chdir(tmp_path)
    fake_results(load_study(study_file(tmp_path, "a.toml", "[5.0]")))
    with pytest.raises(StudyError, match="another study file"):
        run_study(study_file(tmp_path, "b.toml", "[5.0]"), workers=1, quiet=True)


def test_same_file_edited_resumes_and_output_option_separates(tmp_path):
    """Real runs: a.toml, then a.toml with one more speed (resumes), then b.toml of the same name
    refused, then b.toml with --output beside it."""
    p = study_file(tmp_path, "a.toml", "[6.0]")
    r = subprocess.run(
        CLI + ["study", "run", "a.toml", "-w", "1"], cwd=tmp_path, capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "results/coll/runs.json").read_text())["source"] == str(p)
    study_file(tmp_path, "a.toml", "[6.0, 9.0]")
    r = subprocess.run(
        CLI + ["study", "run", "a.toml", "-w", "1"], cwd=tmp_path, capture_output=True, text=True
    )
    assert r.returncode == 0 and "1 run now, 1 already completed" in r.stdout, r.stderr
    study_file(tmp_path, "b.toml", "[6.0]")
    r = subprocess.run(
        CLI + ["study", "run", "b.toml", "-w", "1"], cwd=tmp_path, capture_output=True, text=True
    )
    assert r.returncode == 2 and "holds the results of another study file" in r.stderr
    r = subprocess.run(
        CLI + ["study", "run", "b.toml", "-w", "1", "--output", "results/coll_b"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0 and "1 run now" in r.stdout, r.stderr
    assert (tmp_path / "results/coll_b/summary.csv").exists()
    assert len((tmp_path / "results/coll/summary.csv").read_text().splitlines()) == 3  # a's two runs kept


# --- output paths ------------------------------------------------------------------------


def test_run_out_that_is_a_file_or_cannot_be_created(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("x")
    code, out = invoke(["run", "--out", "afile", "--duration", "0.01"])
    assert (
        code == 2 and one_line_error(out) == "error: --out afile is a file, not a folder: give a folder path"
    )
    code, out = invoke(["run", "--out", "afile/sub", "--duration", "0.01"])
    assert code == 2 and "afile/sub cannot be created" in one_line_error(out) and "is a file" in out
    if os.path.isdir("/proc/self"):
        code, out = invoke(["run", "--out", "/proc/x", "--duration", "0.01"])
        assert code == 2 and one_line_error(out).startswith("error: --out /proc/x cannot be created")
    assert (tmp_path / "afile").read_text() == "x"


def test_study_output_that_is_a_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("x")
    study_file(tmp_path, "o.toml", "[5.0]", name="o", extra='output = "afile"\n')
    code, out = invoke(["study", "run", "o.toml"])
    assert (
        code == 2
        and one_line_error(out)
        == "error: o.toml: results folder afile is a file, not a folder: give a folder path"
    )
    assert (tmp_path / "afile").read_text() == "x"


# --- a study file read from another directory, a results folder --------------------------


def test_status_view_plot_summary_from_another_directory(tmp_path, monkeypatch):
    home, elsewhere = tmp_path / "proj", tmp_path / "elsewhere"
    home.mkdir()
    elsewhere.mkdir()
    monkeypatch.chdir(home)
    p = study_file(home, "s.toml", "[5.0, 6.0]", name="s")
    fake_results(load_study(p), completed=[0])
    code, out = invoke(["study", "status", str(p)])
    assert code == 0 and "2 runs: 1 done, 0 failed, 1 pending" in out
    monkeypatch.chdir(elsewhere)
    code, out = invoke(["study", "status", str(p)])  # results are where `study run` ran: not here
    assert code == 0 and out == (
        f"study s: 2 runs, all pending: {elsewhere}/results/s does not exist ([study] "
        "output is relative to the directory `study run` ran in: run this there, or "
        "give the results folder)"
    )
    code, out = invoke(["study", "status", str(home / "results" / "s")])  # a results folder is accepted
    assert code == 0 and "2 runs: 1 done, 0 failed, 1 pending" in out
    for args in (["view", str(p), "abc"], ["plot", str(p)], ["study", "summary", str(p)]):
        code, out = invoke(args)
        assert code == 2 and one_line_error(out) == (
            f"error: no results of study s: {elsewhere}/results/s does not "
            "exist ([study] output is relative to the directory `study run` "
            "ran in: run this there, or give the results folder)"
        ), args
    code, out = invoke(["study", "status", str(elsewhere)])
    assert code == 2 and "is not a study results folder" in one_line_error(out)
    code, out = invoke(["view", str(home / "results" / "s"), "zzz"])
    assert code == 3 and "no run 'zzz'" in out


# --- trackbench run: names -----------------------------------------------------------------


@pytest.mark.parametrize(
    "args,pattern",
    [
        (["--name", "a b/c"], "name 'a b/c' is not allowed: it names the files, so no /"),
        (["--set", "name=../x"], "name '../x' is not allowed"),
        (["--name", ".hidden"], "name '.hidden' is not allowed"),
        (["--name", "a", "--set", "name=b"], "--name 'a' and --set name='b' disagree"),
    ],
)
def test_run_names_that_are_not_file_names(tmp_path, args, pattern):
    code, out = invoke(["run", "--out", str(tmp_path / "o"), "--duration", "0.01"] + args)
    assert code == 2 and pattern in one_line_error(out)
    assert not (tmp_path / "o").exists()


def test_taken_default_name_suggests_name_and_set_name_is_honoured(tmp_path):
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    (out_dir / "paper_step.nc").write_text("the first example's result")
    code, out = invoke(["run", "--set", "speed=15", "--duration", "0.01", "--out", str(out_dir)])
    assert code == 2 and one_line_error(out) == (
        f"error: {out_dir}/paper_step.nc exists: give this run its own name "
        "with --name NAME (or another --out), or --force to replace it"
    )
    code, out = invoke(["run", "--set", "name=foo", "--duration", "0.01", "--out", str(out_dir)])
    assert code == 0, out
    assert f"written: {out_dir}/foo.nc" in out and f"written: {out_dir}/foo.rrd" in out  # the recording too
    assert (out_dir / "foo.nc").exists() and (out_dir / "foo.rrd").exists()
    assert "trackbench run 'foo'" in out
    assert (out_dir / "paper_step.nc").read_text() == "the first example's result"


# --- help and version ----------------------------------------------------------------------


def test_version_and_help_shows_flags_and_choices():
    from trackbench.version import __version__

    code, out = invoke(["--version"])
    assert code == 0 and out.startswith(f"trackbench {__version__}")
    _, run_help = invoke(["run", "--help"])
    _, study_help = invoke(["study", "run", "--help"])
    for text in (run_help, study_help):
        assert re.search(r"--force\s+<bool>", text) is None and re.search(r"--force\s+\S", text)
        assert re.search(r"--storage\s+full\|compact", text)
    assert re.search(r"--executor\s+local\|dask", study_help)
    assert "[study] storage" in study_help and "[study] output" in study_help  # not eaten as markup
    for args in ([], ["study"], ["run"], ["study", "run"], ["plot"]):  # Typer's own --help flag too
        _, text = invoke(args + ["--help"])
        assert re.search(r"--help\s+Show this message", text) and "<bool>" not in text


def test_params_lists_each_unit_in_its_own_column():
    from trackbench.cli.single_run import parameter_table

    table = parameter_table().splitlines()
    assert table[0].split() == ["name", "paper", "value", "unit", "allowed"]
    rows = {r.split()[0]: r for r in table[1:] if r.strip()}
    assert rows["drive.gain_p"].split()[1:5] == ["30000.0", "N", "m", "s/m"]
    assert rows["track.link_stiffness"].split()[2] == "N/m"


@pytest.mark.parametrize(
    "args, says",
    [
        (["run", "--duration", "x"], "trackbench run: Invalid value for '--duration'"),
        (
            ["study", "run", "s.toml", "--workers", "abc"],
            "trackbench study run: Invalid value for '--workers'",
        ),
        (["run", "--bogus", "1"], "trackbench run: No such option: --bogus"),
        (["nosuch"], "trackbench: No such command 'nosuch'"),
    ],
)
def test_a_mistyped_option_is_one_line_too(args, says):
    r = subprocess.run(CLI + args, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and r.stdout == ""
    err = one_line_error(r.stderr.strip())
    assert says in err and err.endswith("--help')")
