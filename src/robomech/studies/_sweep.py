"""Report of a sweep store (``robomech sweep ... --report`` and the ``sweep-demo`` study).

Synthesis studies: the Pareto front of their objectives (pymoo non-dominated sorting) drawn pairwise over
every feasible design, and the front as a table.  Tolerance studies: histograms of the pointing-error
metrics over the Monte Carlo samples, their percentiles, and the study's own summary tables (the
sensitivity ranking).  Reads only the Zarr store, so it also reports a sweep computed on a cluster.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from robomech.explore import Metric, Objective, Variable, available_studies, open_results, pareto_front

from ._core import StudyResult, Table
from ._plot import plt, save_figure
from ._report import write_study_report

__all__ = ["sweep_result", "write_sweep_report"]

# Percentiles of the Monte Carlo distribution reported for a tolerance study.
PERCENTILES = (50, 90, 95, 99)
# Rows of the Pareto-front table (the front itself is in results.json / the store).
FRONT_ROWS = 20


def sweep_result(store: Path, out_dir: Path, name: str = "sweep", prefix: str = "") -> StudyResult:
    """A StudyResult (tables, PNGs ``out_dir/<prefix><figure>.png``) from the sweep store ``store``."""
    r = open_results(store, as_dict=True)
    a = r["attrs"]
    study = _study_of(a, r)
    res = StudyResult(
        name=name,
        title=f"Sweep: {a['title']}",
        source=f"robomech sweep {a['study']} (robomech {a['robomech_version']}), store {store}",
        summary=(
            f"{r['designs'].shape[0]} designs ({a['fingerprint']['sampler']} sampling, seed "
            f"{a['fingerprint']['seed']}), {int(np.sum(r['chunk_done']))} of {r['chunk_done'].size} chunks "
            f"stored; {int(np.sum(r['design_ok']))} designs accepted by the parameter dataclass."
        ),
    )
    res.tables.append(
        Table(
            "Design variables",
            ["name", "kind", "range or sigma", "unit", "description"],
            [
                [
                    v["name"],
                    v["kind"],
                    f"[{v['low']:.4g}, {v['high']:.4g}]"
                    if v["kind"] == "range"
                    else f"sigma {v['sigma']:.4g}",
                    v["unit"],
                    v["description"],
                ]
                for v in a["variables"]
            ],
        )
    )
    out_dir.mkdir(parents=True, exist_ok=True)
    scalar = [m for m in study.metrics if m.shape == () and m.dtype != "bool"]
    stats = []
    for m in scalar:
        x = np.asarray(r[m.name], float)
        f = x[np.isfinite(x)]
        stats.append([m.name, m.unit, f.size, *(np.percentile(f, [0, 50, 100]) if f.size else ["—"] * 3)])
    res.tables.append(
        Table("Metrics over the designs", ["metric", "unit", "finite", "min", "median", "max"], stats)
    )
    if study.objectives:
        _pareto(res, r, study, out_dir, prefix)
    if any(v["kind"] == "range" for v in a["variables"]) and scalar:
        _sensitivity(res, r, study, scalar, out_dir, prefix)
    if any(v["kind"] == "normal" for v in a["variables"]):
        _tolerance(res, r, scalar, out_dir, prefix)
    if study.summarize is not None:
        for t in study.summarize(study, r):
            res.tables.append(Table(t["title"], t["columns"], t["rows"], note=t.get("note", "")))
    res.data = {"attrs": a, "n_designs": int(r["designs"].shape[0])}
    return res


def _study_of(a: dict, r: dict):
    """The registered study of the store, or one rebuilt from its attributes (a model study, whose
    description lives in the user's file): name, variables, metrics and objectives."""
    studies = available_studies()
    if a["study"] in studies:
        return studies[a["study"]]
    variables = tuple(
        Variable(v["name"], v["low"], v["high"], unit=v["unit"], description=v["description"])
        if v["kind"] == "range"
        else Variable(v["name"], kind="normal", sigma=v["sigma"], unit=v["unit"])
        for v in a["variables"]
    )
    metrics = tuple(
        Metric(
            m["name"],
            m["unit"],
            m["description"],
            shape=tuple(np.asarray(r[m["name"]]).shape[1:]),
            dtype="bool" if np.asarray(r[m["name"]]).dtype == bool else "float64",
        )
        for m in a["metrics"]
    )
    objectives = tuple(Objective(o["metric"], o["sense"]) for o in a.get("objectives", []))
    return SimpleNamespace(
        name=a["study"], variables=variables, metrics=metrics, objectives=objectives, summarize=None
    )


# Designs needed for a rank correlation to be reported (fewer: the sensitivity table is left out).
MIN_SENSITIVITY_DESIGNS = 8


def _sensitivity(res: StudyResult, r: dict, study, metrics, out_dir: Path, prefix: str) -> None:
    """Spearman rank correlation of each scalar metric with each range variable over the designs where
    the metric is finite (scipy.stats.spearmanr): +1 the metric grows monotonically with the variable."""
    from scipy.stats import spearmanr

    X = np.asarray(r["designs"], float)
    cols = [i for i, v in enumerate(study.variables) if v.kind == "range"]
    names = [study.variables[i].name for i in cols]
    rho = np.full((len(metrics), len(cols)), np.nan)
    for a, m in enumerate(metrics):
        y = np.asarray(r[m.name], float)
        ok = np.isfinite(y) & np.asarray(r["design_ok"], bool)
        if ok.sum() < MIN_SENSITIVITY_DESIGNS or np.ptp(y[ok]) == 0:
            continue
        for b, i in enumerate(cols):
            rho[a, b] = spearmanr(X[ok, i], y[ok]).statistic
    if not np.isfinite(rho).any():
        return
    fig, ax = plt.subplots(figsize=(1.2 * len(cols) + 3, 0.5 * len(metrics) + 1.8))
    im = ax.imshow(rho, cmap="RdBu_r", vmin=-1, vmax=1, aspect="auto")
    ax.set_xticks(range(len(cols)), names)
    ax.set_yticks(range(len(metrics)), [m.name for m in metrics])
    for (a, b), v in np.ndenumerate(rho):
        if np.isfinite(v):
            ax.text(b, a, f"{v:+.2f}", ha="center", va="center", fontsize=8)
    fig.colorbar(im, ax=ax, label="Spearman rank correlation")
    ax.set_title(f"{study.name}: sensitivity of each metric to each variable")
    res.figures.append(
        save_figure(
            fig,
            out_dir,
            prefix + "sensitivity",
            "Spearman rank correlation of each metric with each design variable over the sampled designs.",
        )
    )
    res.tables.append(
        Table(
            "Sensitivity: Spearman rank correlation of each metric with each variable",
            ["metric", *names],
            [[m.name, *(float(x) if np.isfinite(x) else "—" for x in rho[a])] for a, m in enumerate(metrics)],
        )
    )


def _pareto(res: StudyResult, r: dict, study, out_dir: Path, prefix: str) -> None:
    objs = study.objectives
    front = pareto_front(r, objs)
    names = [o.metric for o in objs]
    feasible = np.all([np.isfinite(np.asarray(r[n], float)) for n in names], axis=0) & r["design_ok"]
    pairs = list(itertools.combinations(range(len(objs)), 2))
    fig, axes = plt.subplots(1, len(pairs), figsize=(5 * len(pairs), 4.2), squeeze=False)
    units = {m.name: m.unit for m in study.metrics}
    for ax, (i, j) in zip(axes[0], pairs, strict=True):
        xi, xj = np.asarray(r[names[i]], float), np.asarray(r[names[j]], float)
        ax.plot(xi[feasible], xj[feasible], ".", color="0.7", ms=4, label="feasible designs")
        ax.plot(
            xi[front], xj[front], "o", color="C3", ms=5, mfc="none", label="Pareto front (all objectives)"
        )
        ax.set_xlabel(f"{names[i]} ({units[names[i]]}, {objs[i].sense})")
        ax.set_ylabel(f"{names[j]} ({units[names[j]]}, {objs[j].sense})")
        ax.grid(True, alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(f"{study.name}: {front.size} non-dominated of {int(feasible.sum())} feasible designs")
    res.figures.append(
        save_figure(
            fig,
            out_dir,
            prefix + "pareto_front",
            "Pairwise views of the objectives; circles: designs no other design beats in every objective.",
        )
    )
    cols = [v.name for v in study.variables]
    order = front[np.argsort(-np.asarray(r[names[0]], float)[front] * (1 if objs[0].sense == "max" else -1))]
    rows = [[int(k), *r["designs"][k].tolist(), *(float(r[n][k]) for n in names)] for k in order[:FRONT_ROWS]]
    res.tables.append(
        Table(
            f"Pareto front ({front.size} designs; first {min(FRONT_ROWS, front.size)} by {names[0]})",
            ["design", *cols, *names],
            rows,
        )
    )
    res.data["pareto_front"] = front.tolist()


def _tolerance(res: StudyResult, r: dict, metrics, out_dir: Path, prefix: str) -> None:
    err = [m for m in metrics if m.unit == "rad"]
    fig, axes = plt.subplots(1, len(err), figsize=(4.2 * len(err), 3.8), squeeze=False)
    rows = []
    for ax, m in zip(axes[0], err, strict=True):
        x = np.asarray(r[m.name], float)
        x = x[np.isfinite(x)]
        ax.hist(np.degrees(x), bins=40, color="C0")
        ax.set_xlabel(f"{m.name} (deg)")
        ax.set_ylabel("as-built samples")
        ax.grid(True, alpha=0.3)
        if x.size:
            rows.append(
                [m.name, *np.degrees(np.percentile(x, PERCENTILES)).tolist(), float(np.degrees(x.max()))]
            )
    fig.suptitle("Pointing error over the workspace, distribution over the Monte Carlo samples")
    res.figures.append(
        save_figure(
            fig,
            out_dir,
            prefix + "tolerance_histograms",
            "Histograms of each as-built mechanism's pointing error.",
        )
    )
    res.tables.append(
        Table(
            "Pointing error percentiles over the Monte Carlo samples (degrees)",
            ["metric", *(f"P{p}" for p in PERCENTILES), "worst case"],
            rows,
        )
    )


def write_sweep_report(store: Path, out_dir: Path) -> Path:
    """Write ``report.md``, ``report.html``, ``results.json`` and PNGs of the store; return report.md."""
    res = sweep_result(Path(store), Path(out_dir))
    return write_study_report(res, Path(out_dir))["md"]
