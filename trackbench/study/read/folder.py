"""A study file or its results folder -> the study: its runs (a search's as far as the folder
has them), where its results are, and one-line errors when they are not there."""

import os
from pathlib import Path

from trackbench.study import store
from trackbench.study.spec.search import SearchSpec
from trackbench.study.spec.study_file import Run, Study, StudyError, load_study


def _study_of(path):
    """A study file, or a results folder (its runs.json, written by `study run`). A study file
    with [search] gets the runs its search has asked for so far (limits.replay)."""
    path = Path(path)
    if not path.is_dir():
        return _searched(load_study(path))
    m = store.read_json(path / "runs.json")
    if m is None:
        return load_study(path / "study.toml", output=path)
    search = SearchSpec(**m["search"]) if m.get("search") else None
    study = Study(name=m["name"], description=m["description"], source=path / "study.toml", output=path,
                  replicates=m["replicates"], base={}, param_names=m["param_names"], search=search,
                  points=m.get("points", []))
    study.runs = [Run(**r) for r in m["runs"]]
    return study


def _searched(study):
    """A study file's study, with [search] the runs its search has asked for so far added."""
    if study.search is not None and Path(study.output).is_dir():
        from trackbench.study.read.limits import replay
        replay(study)
    return study


def missing_folder(study):
    """'<folder> does not exist (why it was looked for there)': a study file's missing results folder."""
    out = Path(study.output)
    where = "" if out.is_absolute() else (" ([study] output is relative to the directory `study run` ran in: "
                                          "run this there, or give the results folder)")
    return f"{os.path.abspath(out)} does not exist{where}"


def study_folder(path):
    """A study file or its results folder -> (study, results folder); StudyError (one line)
    when the path or the results folder does not exist. A study file's folder is its [study]
    output (default results/<name>) relative to the current directory, as `study run` puts it."""
    path = Path(path)
    if not path.exists():
        raise StudyError(f"{path} does not exist")
    if path.is_dir():
        if not ((path / "runs.json").is_file() or (path / "study.toml").is_file()):
            raise StudyError(f"{path} is not a study results folder (no runs.json or study.toml inside)")
        return _study_of(path), path
    study = load_study(path)
    if not Path(study.output).is_dir():
        raise StudyError(f"no results of study {study.name}: {missing_folder(study)}")
    return _searched(study), Path(study.output)


def study_output(toml_path):
    """The results folder of a study TOML, found as `study run` puts it (study_folder);
    ValueError (one line) when the file is bad or its results do not exist."""
    try:
        return study_folder(toml_path)[1]
    except StudyError as e:
        raise ValueError(str(e)) from None
