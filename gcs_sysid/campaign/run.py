"""The campaign loop, its acceptance checks and the command-line entry."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..aero.table import MOMENT_COEFFICIENTS
from ..airframe import load_airframe
from ..errors import InputError
from .config import COEF_NOISE, CampaignConfig
from .flights import errors, fit, fit_plan, flown_check, fly, sigma_in, standard_doc, suggest, validation_doc
from .render import campaign_figure, campaign_markdown

__all__ = ["run_campaign", "run_campaign_cli"]


def run_campaign(airframe_path: str | Path, model_path: str | Path, out_dir: str | Path | None,
                 config: CampaignConfig = CampaignConfig(), progress=print) -> dict[str, Any]:
    """Run the closed-loop campaign (module docstring) and write ``campaign.json``, ``campaign.md``, ``campaign.png``.

    Args:
        airframe_path: airframe TOML (its ``[limits]`` bound every suggestion).
        model_path: truth aero model TOML (``docs/model-file.md``).
        out_dir: output directory (created), or None to write nothing.
        config: :class:`CampaignConfig`.
        progress: callable taking one line of text (``print``), or None.

    Returns:
        the result document (also ``campaign.json``): ``runs`` (per seed: ``flights`` rows per arm with
        ``errors_pct`` and ``sigma`` per coefficient), ``acceptance`` (the three checks per seed and overall).

    Raises:
        InputError: bad files or settings; an airframe whose limits cannot be defaulted.
    """
    from ..jaxconfig import enable_x64
    from ..maneuvers import check_peaks, effective_limits
    from ..sim import load_model

    enable_x64()
    say = progress or (lambda s: None)
    airframe = load_airframe(airframe_path)
    truth = load_model(model_path)
    if airframe.limits is None:
        raise InputError(f"{airframe_path}: campaign needs a [limits] table (there is no flown envelope to default "
                         f"it from before the first flight)")
    lim = effective_limits(airframe)
    throw = dict(lim.throw)
    V0 = round(lim.V_min + 0.45 * (lim.V_max - lim.V_min), 1)
    runs = []
    for seed in config.seeds:
        rng = np.random.default_rng(seed)
        val = fly(airframe, truth, validation_doc(lim, throw, "validation", config.flight_s), config.rate_hz, rng,
                  noise=False)
        X_test, Y_test = val.X, val.Y
        f1 = fly(airframe, truth, standard_doc(V0, config, seed, throw, None, None, "standard-1")[0],
                  config.rate_hz, rng)
        model1 = fit(f1.X, f1.Y, config, seed)
        env1, sug1 = suggest(model1, f1.X, f1.Y, airframe, config, lim)
        regions = {}
        for c in MOMENT_COEFFICIENTS:
            pts = [r.points for r in env1.regions_of(c)]
            if pts:
                regions[c] = np.vstack(pts)
        top = sug1[0] if sug1 else None
        target_pts = None
        if top is not None:
            for r in env1.regions:
                if r.coefficient == top.region["coefficient"] and list(r.axes) == top.region["axes"] and \
                        all(abs(r.bounds[k][0] - v[0]) < 1e-12 for k, v in top.region["bounds"].items()):
                    target_pts = r.points
                    break
        row1 = {"flight": 1, "kind": "standard", "errors_pct": errors(model1, X_test, Y_test),
                "sigma": sigma_in(model1, regions), "peaks": f1.peaks}
        if target_pts is not None:
            row1["target_sigma"] = sigma_in(model1, {top.coefficients[0]: target_pts})[top.coefficients[0]]
        say(f"seed {seed}: flight 1 (standard) errors "
            + " ".join(f"{c} {e:.0f}%" for c, e in row1["errors_pct"].items()))
        arms: dict[str, list[dict]] = {"suggested": [row1], "standard": [row1]}
        violations: list[str] = []
        flown_bad: list[str] = []
        for arm in ("suggested", "standard"):
            model, X, Y, sug = model1, f1.X, f1.Y, sug1
            for k in range(2, config.flights + 1):
                if arm == "suggested":
                    if not sug:
                        say(f"seed {seed}: no suggestion before flight {k}; flying a standard set")
                        doc, used = standard_doc(V0, config, seed * 100 + k, throw, None, None, f"s{k}")
                        flown = []
                    else:
                        doc, flown = fit_plan(list(sug), airframe, config, seed * 100 + k)
                    for s in flown:
                        bad = check_peaks(s.expected, lim)
                        violations += [f"seed {seed} flight {k} #{s.rank}: {b}" for b in bad]
                    budget = sum(s.input_s for s in flown)
                    amps = {}
                    for s in flown:
                        for c, a in s.amplitudes_rad.items():
                            amps[c] = max(amps.get(c, 0.0), math.degrees(a))
                    arms.setdefault("_budget", []).append({"flight": k, "input_s": budget, "amps": amps})
                else:
                    b = arms["_budget"][k - 2]
                    doc, used = standard_doc(V0, config, seed * 100 + k, throw, b["input_s"] or None,
                                              b["amps"] or None, f"std{k}")
                    flown = []
                fl = fly(airframe, truth, doc, config.rate_hz, rng)
                if arm == "suggested" and flown:
                    flown_bad += [f"seed {seed} flight {k}: {b}" for b in flown_check(fl.peaks, lim)]
                X, Y = np.vstack([X, fl.X]), np.vstack([Y, fl.Y])
                if config.refit:
                    model = conditioned = fit(X, Y, config, seed)
                else:
                    # what the flight taught, under the hyperparameters it was designed with: sigma
                    # is compared at fixed hyperparameters (a refresh rescales the variance itself)
                    conditioned = model.update(fl.X, fl.Y)
                    model = conditioned.refresh_hyperparameters()
                row = {"flight": k, "kind": arm, "errors_pct": errors(model, X_test, Y_test),
                       "sigma": sigma_in(conditioned, regions), "peaks": fl.peaks,
                       "flown": [{"rank": s.rank, "kind": s.kind, "controls": list(s.controls),
                                  "coefficients": list(s.coefficients), "V": s.flight_condition["V"]} for s in flown]}
                if target_pts is not None:
                    row["target_sigma"] = sigma_in(conditioned, {top.coefficients[0]: target_pts})[top.coefficients[0]]
                arms[arm].append(row)
                say(f"seed {seed}: flight {k} ({arm}) errors "
                    + " ".join(f"{c} {e:.0f}%" for c, e in row["errors_pct"].items()))
                if arm == "suggested" and k < config.flights:
                    _, sug = suggest(model, X, Y, airframe, config, lim)
        budget = arms.pop("_budget", [])
        runs.append({"seed": seed, "arms": arms, "budget": budget, "violations": violations, "flown_outside": flown_bad,
                     "target": None if top is None else {"coefficient": top.coefficients[0], "region": top.region,
                                                         "fix": top.fix}})
    doc = {"airframe": str(airframe_path), "truth_model": str(model_path), "config": _cfg_dict(config),
           "limits": lim.to_dict(),
           "identification": "true regressors + coefficient noise COEF_NOISE "
                             f"{COEF_NOISE.tolist()} at {config.rate_hz:g} Hz; after each flight the GP is "
                             + ("re-learned on all data" if config.refit else
                                "updated incrementally (the new rows added; sigma read at the hyperparameters the "
                                "flight was designed with; then hyperparameters and inducing points refreshed on the "
                                "stored rows for the errors and the next design)"),
           "runs": runs, "acceptance": _acceptance(runs, lim)}
    if out_dir is not None:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        from ..report.store import jsonable

        (out / "campaign.json").write_text(json.dumps(jsonable(doc), indent=1, allow_nan=False))
        (out / "campaign.md").write_text(campaign_markdown(doc), encoding="utf-8")
        (out / "campaign.png").write_bytes(campaign_figure(doc))
    return doc


def _cfg_dict(c: CampaignConfig) -> dict:
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in c.__dict__.items()}


def _acceptance(runs: list[dict], lim) -> dict[str, Any]:
    per = []
    for run in runs:
        s, b = run["arms"]["suggested"], run["arms"]["standard"]
        r: dict[str, Any] = {"seed": run["seed"]}
        if "target_sigma" in s[0] and len(s) > 1:
            d_s = s[0]["target_sigma"] - s[1]["target_sigma"]
            d_b = s[0]["target_sigma"] - b[1]["target_sigma"]
            r["sigma_drop_suggested"], r["sigma_drop_standard"] = d_s, d_b
            r["sigma_drop_ratio"] = d_s / d_b if d_b > 0 else float("inf")
            r["sigma_2x"] = bool(d_s >= 2.0 * max(d_b, 0.0) and d_s > 0)
        n = min(len(s), len(b), 4) - 1
        if n >= 1:
            r["after_flights"] = n + 1
            r["moment_errors_suggested"] = {c: s[n]["errors_pct"][c] for c in MOMENT_COEFFICIENTS}
            r["moment_errors_standard"] = {c: b[n]["errors_pct"][c] for c in MOMENT_COEFFICIENTS}
            r["moments_better"] = bool(all(s[n]["errors_pct"][c] < b[n]["errors_pct"][c] for c in MOMENT_COEFFICIENTS))
        r["inside_limits"] = not run["violations"]
        r["flown_inside_limits"] = not run.get("flown_outside")
        per.append(r)
    return {"per_seed": per,
            "sigma_2x_all": all(p.get("sigma_2x", False) for p in per),
            "moments_better_all": all(p.get("moments_better", False) for p in per),
            "inside_limits_all": all(p["inside_limits"] for p in per),
            "flown_inside_limits_all": all(p["flown_inside_limits"] for p in per)}


def run_campaign_cli(airframe: str, model: str, flights: int, seeds: str, out: str, refit: bool = False,
                     write_to: str | Path | None = None, gp_noise: str | None = None) -> int:
    """``gcs-sysid campaign``: parse the seeds, run, print the acceptance lines; returns the exit code.

    ``write_to``: where the files are written (the CLI's staging folder, moved to ``out`` when
    complete); None writes into ``out``. ``gp_noise``: :attr:`CampaignConfig.gp_noise` (None: its default).

    Raises:
        InputError: seeds that are not comma-separated non-negative integers, or see :func:`run_campaign`.
    """
    try:
        seed_list = tuple(int(x) for x in seeds.split(",") if x.strip())
    except ValueError:
        raise InputError(f"--seeds must be comma-separated integers, got {seeds!r}") from None
    if not seed_list or min(seed_list) < 0:
        raise InputError(f"--seeds must be comma-separated non-negative integers, got {seeds!r}")
    doc = run_campaign(airframe, model, out if write_to is None else write_to,
                       CampaignConfig(flights=flights, seeds=seed_list, refit=refit,
                                      **({} if gp_noise is None else {"gp_noise": gp_noise})))
    acc = doc["acceptance"]
    print(f"wrote {Path(out) / 'campaign.md'}: sigma drop >= 2x standard: {acc['sigma_2x_all']}; "
          f"Cl Cm Cn error below standard: {acc['moments_better_all']}; designed inside limits: "
          f"{acc['inside_limits_all']}; flown inside limits: {acc['flown_inside_limits_all']}")
    return 0
