"""``tribodem fretting study``: Lu (2018) chapter 6 (the criteria study) as one call,
:func:`study`.

Chapter 6 runs the seed's case (crossed 8 mm EN24T cylinders, 100 N, the 0.6 mm stroke) with
each material evolution criterion and compares the wear it predicts: one cycle for the von
Mises, vertical stress (S22), equivalent plastic strain (here DFDI, eqs 6.1-6.2) and SWT
(eqs 6.3-6.8) criteria; 30 cycles for the shear (eq 6.9) and the energy criteria, and the
shear criterion with cycle-jumping to 110 cycles (figs 6.14-6.16). Here every stage is one
fretting run of the configured case and first-body backend (``--solver``) in its own folder
``OUT/<stage>/`` (resumable, with its own outputs); ``study.json`` / ``study.md`` put every
number beside the seed's and order the criteria by the wear they predict per cycle.

Readings (stated in ``study.json``): "averaged wear depth over all nodes in the wear scar" is
our ``wear_depth_mean_scar_*`` (the mean over the grid points with wear); the equivalent
plastic strain criterion of section 6.5 is run as DFDI (the seed's threshold on the
equivalent plastic strain with eq 6.2's failure strain); a stage whose criterion needs what
the backend lacks (DFDI needs the ``plastic`` capability) is reported as skipped with the
reason. With a finite-element backend the stages share a ccx job cache (``OUT/ccx_cache``,
``[fe] cache``): the first cycle's job is the same for every criterion (wear is applied after
the cycle), so the one-cycle stages run ccx once. The seed compares the predictions with
an experiment whose data it gives only as figures, so the "closest to experiment" part of
its ranking cannot be measured here: the study gives our ordering of the predicted wear per
cycle beside the seed's ordering.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tribodem.fretting.case import WINDOW_RADII, FrettingCase, check_compatible, preflight
from tribodem.fretting.config import (
    RESUME_MAY_CHANGE,
    FrettingConfig,
    resolve_config,
    runs_ccx,
)
from tribodem.fretting.criteria import CRITERIA
from tribodem.fretting.output import CHECKPOINT
from tribodem.fretting.record import read_study, study_diffs
from tribodem.fretting.runner import Echo, run
from tribodem.io import runs
from tribodem.io.config import ConfigError, dump_toml, merge
from tribodem.io.record import ConfigSource, RunResult, as_out, may_change_text
from tribodem.io.results import write_csv, write_figure, write_json, write_text

#: The seed's numbers (chapter 6 text; depths in m, stresses in Pa; the largest DFDI after one
#: cycle, "approximately 6" lower and "approximately 4" upper, section 6.5).
SEED = {
    "von_mises": {"mean_scar_depth_lower_m": 0.1066e-3, "max_von_mises_Pa": 1600e6},
    "s22": {"mean_scar_depth_lower_m": 0.157e-3, "mean_scar_depth_upper_m": 0.102e-3,
            "max_s22_Pa": 1400e6},
    "dfdi": {"mean_scar_depth_lower_m": 0.0456e-3, "mean_scar_depth_upper_m": 0.0463e-3,
             "max_dfdi_lower": 6.0, "max_dfdi_upper": 4.0},
    "swt": {"cycles_to_first_wear_lower": 600, "cycles_to_first_wear_upper": 200_000,
            "cycles_to_first_wear_upper_centre": 200_000},
}
#: Seed numbers that are bounds, not values ("over 200 thousands of cycles are required by the
#: upper first body", section 6.6): ours agrees when it is at least the bound. The seed's
#: figure 6.12 puts the upper body's largest SWT at the contact edges and "very small values"
#: at its centre, so the bound is compared both ways: the whole body and its contact centre.
SEED_LOWER_BOUNDS = {("swt", "cycles_to_first_wear_upper"),
                     ("swt", "cycles_to_first_wear_upper_centre")}
#: The seed's conclusion (section 6.8): from the largest over-prediction to the largest
#: under-prediction of the experiment; shear fits the experiment best.
SEED_ORDER = ("s22", "von_mises", "dfdi", "shear", "energy", "swt")
SEED_CONCLUSION = ("von Mises and S22 grossly over-predict, equivalent plastic strain still "
                   "over-predicts, SWT under-predicts, the energy law under-predicts except "
                   "near 1000 cycles, the shear criterion fits the experiment best")


#: ``--quick`` on a backend without plastic strain: the stage whose criterion needs it (DFDI)
#: runs on the backend's plastic counterpart (the same half-space with EPIC plasticity), so
#: the quick study runs every stage; the full study skips it, with the reason
QUICK_PLASTIC_COUNTERPART = {"elastic": "elastic-plastic"}
#: ``--quick``: the window of a multi-cycle threshold stage (shear, shear_jump) of a point
#: contact, in contact radii of the unworn contact. A rate criterion's window is sized for
#: the scar it predicts (``fretting.case.scar_window``); a threshold criterion's scar is not
#: known in advance, and on the 64^2 quick window of the default 10 radii the 15-cycle
#: shear_jump stage outgrew it at cycle 12 (exit 3); at 20 radii it holds the 15 cycles
QUICK_THRESHOLD_WINDOW_RADII = 2.0 * WINDOW_RADII


@dataclass(frozen=True)
class Stage:
    """One fretting run of the study."""

    name: str  #: folder and key
    criterion: str
    cycles: int
    jump: str = "none"  #: cycle-jumping strategy


def stages(quick: bool = False) -> list[Stage]:
    """The seed's stages (``quick``: 5 and 15 cycles instead of 30 and 110)."""
    n30, n110 = (5, 15) if quick else (30, 110)
    return [Stage("von_mises", "von_mises", 1), Stage("s22", "s22", 1),
            Stage("dfdi", "dfdi", 1), Stage("swt", "swt", 1),
            Stage("shear", "shear", n30), Stage("energy", "energy", n30),
            Stage("shear_jump", "shear", n110, jump="adaptive")]


def stage_config(cfg: FrettingConfig, st: Stage) -> FrettingConfig:
    """The study's case with the stage's criterion, cycles and jumping."""
    return cfg.model_copy(update={
        "cycles": st.cycles,
        "wear": cfg.wear.model_copy(update={"criterion": st.criterion}),
        "jump": cfg.jump.model_copy(update={"strategy": st.jump, "params": {}}),
        "debris": cfg.debris.model_copy(update={"every": None})})


def quick_stage(scfg: FrettingConfig, st: Stage) -> tuple[FrettingConfig, dict[str, Any]]:
    """A stage's config under ``--quick`` (:data:`QUICK_PLASTIC_COUNTERPART`,
    :data:`QUICK_THRESHOLD_WINDOW_RADII`) and what changed, for its row (``solver`` and
    ``quick_note``; empty when nothing did)."""
    notes: dict[str, Any] = {}
    other = QUICK_PLASTIC_COUNTERPART.get(scfg.solver)
    if other is not None:
        try:
            check_compatible(scfg)
        except ConfigError:
            swapped = scfg.model_copy(update={"solver": other})
            check_compatible(swapped)  # the counterpart serves it, or the stage is skipped
            notes["solver"] = other
            notes["quick_note"] = (f"--quick: run on solver {other!r} ({scfg.solver!r} gives "
                                   f"no plastic strain, which {st.criterion} needs)")
            scfg = swapped
    if (scfg.contact.window is None and st.cycles > 1
            and CRITERIA[st.criterion].kind == "threshold"):
        case = FrettingCase.of(scfg)
        if case.contact != "line" and case.hertz_radius > 0:
            window = QUICK_THRESHOLD_WINDOW_RADII * case.hertz_radius
            scfg = scfg.model_copy(update={"contact": scfg.contact.model_copy(
                update={"window": window})})
            notes["quick_note"] = (
                f"--quick: window {window:.4g} m ({QUICK_THRESHOLD_WINDOW_RADII:g} contact "
                f"radii, {scfg.contact.n} points: a threshold criterion's scar is not known "
                "in advance)")
    return scfg, notes


def row_of(st: Stage, summary: dict[str, Any]) -> dict[str, Any]:
    """The study's numbers of one finished stage (from its summary.json)."""
    crit = summary.get("criterion_last_cycle", {})
    n = int(summary["cycles"])
    row: dict[str, Any] = {
        "stage": st.name, "criterion": st.criterion, "cycles": n, "jump": st.jump,
        "cycles_simulated": summary["cycles_simulated"],
        "mean_scar_depth_lower_m": summary["wear_depth_mean_scar_lower_m"],
        "mean_scar_depth_upper_m": summary["wear_depth_mean_scar_upper_m"],
        "max_depth_lower_m": summary["wear_depth_lower_m"],
        "max_depth_upper_m": summary["wear_depth_upper_m"],
        "worn_volume_lower_m3": summary["wear_volume_lower_m3"],
        "wall_time_s": summary["wall_time_s"],
    }
    if summary.get("jump", {}).get("reading"):  # what limited the jumps (FrettingLoop)
        row["jump_reading"] = summary["jump"]["reading"]
    if summary.get("wear_zero_reason"):  # nothing worn: why (fretting.output)
        row["wear_zero_reason"] = summary["wear_zero_reason"]
    # a stage stopped before its first cycle measured nothing (not a zero rate)
    row["mean_scar_depth_per_cycle_lower_m"] = (row["mean_scar_depth_lower_m"] / n if n > 0
                                                else None)
    for key in ("cycles_to_first_wear_upper", "cycles_to_first_wear_lower",
                "cycles_to_first_wear_upper_centre", "max_dfdi_lower", "max_dfdi_upper"):
        if key in crit:
            row[key] = crit[key]
    rep = summary.get("first_body_report", {}).get("cycles", [])
    soft = [c for c in rep if c.get("contact_penalty_scale", 1.0) < 1.0]
    if soft:  # cycles whose ccx job converged only on a softened contact (it wears less)
        row["softened_cycles"] = [int(c["cycle"]) for c in soft]
        row["softest_penalty_scale"] = min(float(c["contact_penalty_scale"]) for c in soft)
    if rep:  # the backend's own peaks (fe: over the integration points of the cycle)
        row["max_von_mises_Pa"] = max(c["max_von_mises_pa"] for c in rep)
        row["max_s22_Pa"] = max(c["max_s22_compressive_pa"] for c in rep)
    elif st.criterion in ("von_mises", "s22") and "max_value_lower" in crit:
        # else the criterion's field maximum over the cycle (von Mises, |sigma_zz|; Pa)
        key = "max_von_mises_Pa" if st.criterion == "von_mises" else "max_s22_Pa"
        row[key] = max(crit["max_value_lower"], crit["max_value_upper"])
    return row


def compare(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Every seed number beside ours: (stage, quantity, seed, ours, ours / seed)."""
    out = []
    by = {r["stage"]: r for r in rows}
    for stage, nums in SEED.items():
        r = by.get(stage)
        for q, seed in nums.items():
            ran = r is not None and not r.get("skipped") and r.get("cycles") != 0
            ours = r.get(q) if ran else None
            bound = (stage, q) in SEED_LOWER_BOUNDS  # an infinite value meets a bound
            ratio = (ours / seed if ours is not None and seed
                     and (math.isfinite(ours) or (bound and ours > 0)) else None)
            agree = None if ratio is None else (ratio >= 1.0 if bound else abs(ratio - 1) <= 0.2)
            out.append({"stage": stage, "quantity": q, "seed": seed, "ours": ours,
                        "ratio": ratio, "seed_is_lower_bound": bound, "within_20pct": agree})
    return out


def ranking(rows: list[dict[str, Any]]) -> list[str]:
    """Criteria ordered by the predicted mean scar depth per cycle on the lower body, largest
    first (SWT by 1 / its projected cycles to first wear when nothing was worn yet)."""
    def rate(r: dict[str, Any]) -> float:
        v = float(r["mean_scar_depth_per_cycle_lower_m"])
        if v == 0 and r.get("cycles_to_first_wear_lower"):
            return -1.0 / float(r["cycles_to_first_wear_lower"])  # below every wearing one
        return v
    done = [r for r in rows if not r.get("skipped") and r.get("cycles") != 0
            and r["stage"] != "shear_jump"]
    return [r["stage"] for r in sorted(done, key=rate, reverse=True)]


def write_markdown(out: Path, rows: list[dict[str, Any]], table: list[dict[str, Any]],
                   order: list[str], solver: str) -> Path:
    """``study.md``: the stages, every seed number beside ours, the two orderings."""
    um = 1e6
    lines = [f"# Lu (2018) chapter 6 criteria study (solver = {solver!r})", "",
             "| stage | cycles (simulated) | mean scar depth lower / upper (um) | max depth "
             "lower / upper (um) | per cycle, lower (um) | SWT cycles to first wear "
             "lower / upper | wall s |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("skipped"):
            lines.append(f"| {r['stage']} | skipped: {r['skipped']} | | | | | |")
            continue
        if not r["cycles"]:
            lines.append(f"| {r['stage']} | none: {r.get('stopped', 'stopped')} | | | | | "
                         f"{r['wall_time_s']:.1f} |")
            continue
        swt = (f"{r.get('cycles_to_first_wear_lower', float('nan')):.4g} / "
               f"{r.get('cycles_to_first_wear_upper', float('nan')):.4g}"
               if "cycles_to_first_wear_lower" in r else "")
        stop = " stopped early" if r.get("stopped") else ""
        lines.append(
            f"| {r['stage']} | {r['cycles']} ({r['cycles_simulated']}){stop} | "
            f"{r['mean_scar_depth_lower_m'] * um:.4g} / {r['mean_scar_depth_upper_m'] * um:.4g}"
            f" | {r['max_depth_lower_m'] * um:.4g} / {r['max_depth_upper_m'] * um:.4g} | "
            f"{r['mean_scar_depth_per_cycle_lower_m'] * um:.4g} | {swt} | "
            f"{r['wall_time_s']:.1f} |")
    lines += [f"\n{r['stage']}, cycle-jumping: {r['jump_reading']}." for r in rows
              if r.get("jump_reading")]
    lines += [f"\n{r['stage']}: {r['quick_note']}." for r in rows if r.get("quick_note")]
    lines += [f"\n{r['stage']}, nothing worn: {r['wear_zero_reason']}." for r in rows
              if r.get("wear_zero_reason")]
    lines += [f"\n{r['stage']}: cycle(s) {_spans(r['softened_cycles'])} of "
              f"{r['cycles']} converged only on a softened contact (penalty x "
              f"{r['softest_penalty_scale']:g} at the softest; a softer contact wears less: "
              "docs/fe.md `retry_from`)." for r in rows if r.get("softened_cycles")]
    lines += ["", "| stage | quantity | seed | ours | ours / seed | within 20 % (a bound "
              "\"> x\": at least x) |",
              "|---|---|---|---|---|---|"]
    for t in table:
        ours = "not run" if t["ours"] is None else f"{t['ours']:.4g}"
        ratio = "" if t["ratio"] is None else f"{t['ratio']:.3g}"
        within = "" if t["within_20pct"] is None else ("yes" if t["within_20pct"] else "no")
        seed = f"> {t['seed']:.4g}" if t.get("seed_is_lower_bound") else f"{t['seed']:.4g}"
        lines.append(f"| {t['stage']} | {t['quantity']} | {seed} | {ours} | {ratio} "
                     f"| {within} |")
    lines += ["", f"Ours, largest predicted wear per cycle first: {', '.join(order)}.",
              f"Seed (section 6.8), largest over-prediction first: {', '.join(SEED_ORDER)}; "
              f"{SEED_CONCLUSION}.", ""]
    return write_text(out / "study.md", "\n".join(lines))


def _spans(cycles: list[int]) -> str:
    """``[1, 2, 3, 5]`` -> ``"1-3, 5"``."""
    out: list[str] = []
    for c in sorted(cycles):
        if out and c == int(out[-1].split("-")[-1]) + 1:
            out[-1] = f"{out[-1].split('-')[0]}-{c}"
        else:
            out.append(str(c))
    return ", ".join(out)


def depth_plot(out: Path, runs_done: dict[str, Path]) -> Path | None:
    """``depth_vs_cycles.png``: mean of the two bodies' max depths against the cycle for the
    multi-cycle stages (figs 6.15-6.16)."""
    import csv

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    multi = {k: p for k, p in runs_done.items() if k in ("shear", "energy", "shear_jump")}
    if not multi:
        return None
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, folder in multi.items():
        with open(folder / "results.csv") as fh:
            rows = list(csv.DictReader(fh))
        c = [int(r["cycle"]) for r in rows]
        d = [float(r["wear_depth_lower_m"]) * 1e6 for r in rows]
        ax.plot(c, d, "o-" if name != "shear_jump" else "--", ms=3, label=name)
    ax.set_xlabel("cycle")
    ax.set_ylabel("max wear depth, lower body (um)")
    ax.legend()
    fig.tight_layout()
    return write_figure(out / "depth_vs_cycles.png", fig)


def select(plan: list[Stage], names: tuple[str, ...] | None) -> list[Stage]:
    """The stages named (all when None); ``ValueError`` naming the allowed ones."""
    if names is None:
        return plan
    known = [s.name for s in plan]
    bad = [n for n in names if n not in known]
    if bad or not names:
        raise ValueError(f"--stages = {','.join(names)!r}: allowed: a comma-separated subset "
                         f"of {','.join(known)}")
    return [s for s in plan if s.name in names]


#: study.csv's first columns (then any other key of a stage's row, in order of appearance)
STUDY_COLUMNS = ("stage", "criterion", "cycles", "jump", "cycles_simulated",
                 "mean_scar_depth_lower_m", "mean_scar_depth_upper_m",
                 "mean_scar_depth_per_cycle_lower_m", "max_depth_lower_m",
                 "max_depth_upper_m", "worn_volume_lower_m3", "wall_time_s")


def write_table(out: Path, rows: list[dict[str, Any]]) -> Path:
    """``study.csv``: one row per stage (:func:`row_of`; a skipped stage: its ``skipped``
    reason), the columns of :data:`STUDY_COLUMNS` first; a list is written as its JSON."""
    cols = list(STUDY_COLUMNS) + [k for k in dict.fromkeys(k for r in rows for k in r)
                                  if k not in STUDY_COLUMNS]

    def cell(v: Any) -> Any:
        return "" if v is None else json.dumps(v) if isinstance(v, list | dict) else v

    return write_csv(out / "study.csv", cols, ([cell(r.get(c)) for c in cols] for r in rows))


@runs.releases_folders
def study(config: ConfigSource = None, out: str | os.PathLike[str] | None = None, *,
          quick: bool = False, resume: bool = False, progress: bool = False,
          solver: str | None = None, stages: Sequence[str] | str | None = None,
          overrides: Mapping[str, Any] | None = None, echo: Echo | None = None
          ) -> RunResult:
    """Lu (2018) chapter 6 into folder ``out``: every stage (von Mises, S22, DFDI, SWT one
    cycle; shear and energy 30; shear with jumping 110; ``quick``: 64^2, 5 and 15 cycles)
    a fretting run of the case in ``out/<stage>/``, then ``study.json``, ``study.md`` and
    ``study.csv`` (one row per stage).

    ``config``: the case (a :class:`~tribodem.fretting.config.FrettingConfig`, a dict
    shaped like the TOML file, a TOML path or None: the seed's crossed cylinders; with
    ``resume``, the study's own); its criterion, cycles and jumping are the stages'.
    ``solver``: the first-body backend; ``stages``: the stages to run (names, or one
    comma-separated string; default all); ``overrides``: over the config (a dict shaped
    like the TOML file). ``resume``: keep the finished stages of the study in ``out``,
    resume the unfinished one. A stage stopped early raises
    :class:`~tribodem.io.runs.RunStopped` after every output is written.
    """
    folder = as_out(out)  # type: ignore[arg-type]  # None is refused there, named
    runs.check_out_dir(folder, "--out", resume=resume,
                       need=("study.toml",) if resume else ())
    ov = merge(dict(overrides or {}), {"solver": solver} if solver is not None else {})
    base = read_study(folder)["config"] if resume and config is None else None
    cfg = resolve_config(config, quick=quick, overrides=ov, base=base)
    only = (None if stages is None else
            tuple(x.strip() for x in stages.split(",")) if isinstance(stages, str) else
            tuple(stages))
    summary = run_study(cfg, folder, quick=quick, resume=resume, progress=progress,
                        echo=echo, only=only)
    return RunResult(folder, summary, "study.csv", list(summary["files"]))


def run_study(cfg: FrettingConfig, out: Path, quick: bool = False, resume: bool = False,
              progress: bool = False, echo: Echo | None = None,
              only: tuple[str, ...] | None = None) -> dict[str, Any]:
    """Every stage (``only``: those named) into ``out/<stage>/`` (a finished stage is kept
    on ``resume``, an unfinished one resumes from its checkpoint); returns ``study.json``'s
    content."""
    out = Path(out)
    runs.check_out_dir(out, "--out", resume=resume, need=("study.toml",) if resume else ())
    try:
        plan = select(stages(quick), only)
    except ValueError as err:
        raise ConfigError(str(err)) from None
    meta = {"config": cfg.record(), "quick": bool(quick)}
    if resume:
        diffs = study_diffs(out, meta)
        if diffs:
            raise ConfigError(f"--resume: the config differs from the study in '{out}': "
                              f"{'; '.join(diffs)}; allowed: the study's values (and its "
                              f"--quick; {may_change_text(RESUME_MAY_CHANGE)})")
    if not resume:  # a resumed stage keeps the grids it started with: run_stage checks it
        check_stages(cfg, plan, out, quick)
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "study.toml", dump_toml(meta))
    rows: list[dict[str, Any]] = []
    done: dict[str, Path] = {}
    for k, st in enumerate(plan):
        row = run_stage(cfg, st, out, f"stage {k + 1}/{len(plan)}", resume=resume,
                        progress=progress, echo=echo, quick=quick)
        rows.append(row)
        if not row.get("skipped"):
            done[st.name] = out / st.name
    return write_study(cfg, out, rows, done, quick)


def stage_run_config(cfg: FrettingConfig, st: Stage, out: Path,
                     quick: bool) -> tuple[FrettingConfig, dict[str, Any]]:
    """The config stage ``st`` runs with (:func:`stage_config`; ``quick``:
    :func:`quick_stage`, its notes returned; the ccx backends share one job cache in
    ``out/ccx_cache``)."""
    scfg = stage_config(cfg, st)
    notes: dict[str, Any] = {}
    if quick:
        try:
            scfg, notes = quick_stage(scfg, st)
        except ConfigError:  # no counterpart serves it either: the stage is skipped
            pass
    if scfg.fe.cache is None and runs_ccx(scfg.solver):
        # the one-cycle stages run the same first-body job: run it once
        scfg = scfg.model_copy(update={"fe": scfg.fe.model_copy(
            update={"cache": str((out / "ccx_cache").resolve())})})
    return scfg, notes


def check_stages(cfg: FrettingConfig, plan: list[Stage], out: Path, quick: bool) -> None:
    """Every stage checked before the study writes anything (:func:`preflight`:
    ``ConfigError`` naming the field: the window, the memory its arrays need, height maps,
    the jumping); a stage its backend cannot serve is left to :func:`run_stage`, which
    skips it with the reason."""
    for st in plan:
        scfg, _ = stage_run_config(cfg, st, out, quick)
        try:
            check_compatible(scfg)
        except ConfigError:
            continue
        preflight(scfg)


def run_stage(cfg: FrettingConfig, st: Stage, out: Path, label: str, *, resume: bool,
              progress: bool, echo: Echo | None, quick: bool = False) -> dict[str, Any]:
    """One stage into ``out/<stage>/`` (kept when it finished before and ``resume``;
    skipped when its criterion needs what the backend lacks; ``quick``:
    :func:`quick_stage`): its row (:func:`row_of`, with ``skipped`` or ``stopped`` saying
    why)."""
    say = echo or (lambda s: None)
    scfg, notes = stage_run_config(cfg, st, out, quick)
    folder = out / st.name
    try:
        check_compatible(scfg)
    except ConfigError as err:
        say(f"{label} {st.name}: skipped ({err})")
        return {"stage": st.name, "criterion": st.criterion, "skipped": str(err)}
    summary_path = folder / "summary.json"
    finished = (resume and summary_path.is_file()
                and json.loads(summary_path.read_text()).get("cycles") == st.cycles)
    stopped = None
    if not finished:
        jumping = f" with {st.jump} jumping" if st.jump != "none" else ""
        note = f" ({notes['quick_note']})" if notes.get("quick_note") else ""
        say(f"{label} {st.name}: criterion {st.criterion}, "
            f"{st.cycles} cycle(s){jumping}{note} -> {folder}")
        try:
            run(scfg, folder, resume=resume and (folder / CHECKPOINT).is_file(),
                progress=progress, echo=echo)
        except runs.RunStopped as err:  # kept: the stage's outputs up to the stop
            stopped = str(err)
            say(f"  {st.name} stopped early: {err}")
        runs.announce(out, folder / CHECKPOINT, resume_hint="add --resume to the same "
                      "command")
    row = {**row_of(st, json.loads(summary_path.read_text())), **notes}
    if stopped is not None or row["cycles"] < st.cycles:
        row["stopped"] = stopped if stopped is not None else f"stopped at cycle {row['cycles']}"
    return row


def write_study(cfg: FrettingConfig, out: Path, rows: list[dict[str, Any]],
                done: dict[str, Path], quick: bool) -> dict[str, Any]:
    """``study.md``, ``study.csv``, the depth plot, ``study.json`` (returned) from the
    stages' rows; ``RunStopped`` after them when a stage stopped early."""
    table = compare(rows)
    order = ranking(rows)
    files = [write_markdown(out, rows, table, order, cfg.solver).name,
             write_table(out, rows).name]
    if cfg.output.figures:
        p = depth_plot(out, done)
        files += [p.name] if p else []
    summary = {"solver": cfg.solver, "quick": bool(quick), "rows": rows, "seed_comparison": table,
               "ranking_ours": order, "ranking_seed": list(SEED_ORDER),
               "seed_conclusion": SEED_CONCLUSION,
               "readings": {
                   "mean_scar_depth": "the seed's 'averaged wear depth over all nodes in the "
                   "wear scar' = mean over the grid points with wear (summary.json "
                   "wear_depth_mean_scar_*)",
                   "equivalent_plastic_strain": "run as DFDI (eqs 6.1-6.2)",
                   "ranking": "ours: by mean scar depth per cycle on the lower body; the "
                   "seed's: against an experiment given only as figures, not measurable here",
               },
               "files": [*files, "study.json", "study.toml"]}
    write_json(out / "study.json", summary)
    early = [r["stage"] for r in rows if r.get("stopped")]
    if early:
        raise runs.RunStopped(f"stage(s) {', '.join(early)} stopped early (see study.json "
                              "'stopped'); study.md and study.json are written with the "
                              "cycles they reached")
    return summary
