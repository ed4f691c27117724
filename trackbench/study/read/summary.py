"""Reading a study: the pandas summary, replicate statistics, open_study / open_study_dataset.
pandas loads in the functions that build frames: finding a study's folder (`study status`)
does without it."""


import numpy as np

from trackbench.outputs import quantities as Q
from trackbench.study import store

SPREAD_LIMIT = 0.05  # replicates: flag a quantity whose (max - min) / |median| exceeds this
# the results in the study table on screen, in its column order (vertical acceleration as min, max)
SCREEN = (
    "peak_wheel_force_y",
    "peak_ground_force_y",
    "peak_link_tension",
    "min_chassis_ay",
    "peak_chassis_ay",
    "min_chassis_vx",
    "peak_seat_acceleration_g",
    "absorbed_power",
    "first_compression_time",
    "peak_sprocket_torque",
    "peak_idler_force",
    "peak_sinkage",
    "mean_drawbar_pull",
    "mean_slip",
)


def peak_columns(study):
    """The summary's peak and mean columns, in summary order (replicate statistics cover these)."""
    return Q.peak_columns(*Q.shape_of(r.scenario for r in study.runs))


def summary_frame(study):
    """One row per run of the study (pending when it has not run), from the runs' run.json."""
    import pandas as pd
    wheels, features = Q.shape_of(r.scenario for r in study.runs)
    results = Q.summary_columns(wheels, features=features)
    rows = []
    for run in study.runs:
        rec = store.read_run(study.output, run.run_id) or {"status": "pending", "status_message": ""}
        res = rec.get("results") or {}
        row = {"run_id": run.run_id, "status": rec["status"], "status_message": rec.get("status_message", ""),
               "variant": run.variant, "replicate": run.replicate}
        row.update({n: run.params.get(n) for n in study.param_names})
        row.update({k: res.get(k) for k in results})
        for k in ("steps", "rejected_steps", "t_final", "wall_time", "solve_time"):
            row[k] = rec.get(k)
        rows.append(row)
    df = pd.DataFrame(rows)
    num = results + ["t_final", "wall_time", "solve_time"]
    df[num] = df[num].astype(float)
    for k in ("steps", "rejected_steps"):
        df[k] = df[k].astype("Int64")
    df.attrs.update(study=study.name, study_dir=str(study.output))
    return df


def replicate_frame(study, df):
    """One row per variant: median, min, max and relative spread of every peak over its completed
    replicates; ``sensitive`` lists the quantities whose spread exceeds 5 %."""
    import pandas as pd
    params = [p for p in study.param_names if p != "seed"]
    rows = []
    for v, g in df.groupby("variant", sort=True):
        ok = g[g.status == "completed"]
        row = {"variant": v, **{p: g[p].iloc[0] for p in params},
               "replicates": len(g), "completed": len(ok)}
        flagged = []
        for q in peak_columns(study):
            x = ok[q].dropna()
            med = float(x.median()) if len(x) else np.nan
            lo, hi = (float(x.min()), float(x.max())) if len(x) else (np.nan, np.nan)
            spread = (hi - lo) / abs(med) if len(x) and med != 0 else np.nan
            row.update({f"{q}_median": med, f"{q}_min": lo, f"{q}_max": hi, f"{q}_spread": spread})
            if spread > SPREAD_LIMIT:
                flagged.append(q)
        row["sensitive"] = " ".join(flagged)
        rows.append(row)
    return pd.DataFrame(rows)


def write_summary(study):
    """Rebuild and write summary.csv (.parquet) (and replicates.csv); returns the frames."""
    df = summary_frame(study)
    store.write_table(df, study.output / "summary")
    rep = None
    if study.replicates > 1:
        rep = replicate_frame(study, df)
        store.write_table(rep, study.output / "replicates")
    return df, rep


def format_table(df, rep=None, params=()):
    """A screen-sized table: the SCREEN quantities in their display units (forces in kN)."""
    import pandas as pd
    show = pd.DataFrame({"run": df.run_id.str[:8], "status": df.status})
    for p in params:
        show[p] = df[p]
    for name in SCREEN:
        q = Q.BY_NAME[name]
        for c in q.present(df.columns):
            show[q.heading.format(q.wheel_of(c))] = q.display(df[c])
    show["wall s"] = df.wall_time
    text = show.to_string(index=False, float_format=lambda x: f"{x:.4g}", na_rep="-")
    bad = df[df.status == "failed"]
    for _, r in bad.iterrows():
        text += f"\nfailed {r.run_id}: {r.status_message}"
    if rep is not None:
        cols = [p for p in params if p != "seed"] + ["completed"]
        t = rep[cols].copy()
        g = Q.BY_NAME["peak_ground_force_y"]
        t[g.heading + " median [min, max]"] = [
            f"{g.display(a):.4g} [{g.display(b):.4g}, {g.display(c):.4g}]" for a, b, c in
            zip(rep[g.name + "_median"], rep[g.name + "_min"], rep[g.name + "_max"])]
        t["spread > 5 %"] = rep.sensitive.replace("", "-")
        text += "\n\nreplicates (median, min, max over seeds; full table in replicates.csv):\n"
        text += t.to_string(index=False)
    return text
