"""campaign.md and campaign.png: renderers of the campaign document (a saved campaign re-renders)."""

from __future__ import annotations

import numpy as np

from ..aero.table import COEFFICIENTS, MOMENT_COEFFICIENTS

__all__ = ["campaign_markdown", "campaign_figure"]


def campaign_markdown(doc: dict) -> str:
    """campaign.md: per seed, a table per arm of held-out error vs truth and sigma in the flagged regions."""
    L = ["# gcs-sysid campaign", "", f"- airframe: {doc['airframe']}", f"- truth model: {doc['truth_model']}",
         f"- identification: {doc['identification']}", ""]
    acc = doc["acceptance"]
    L += ["## Acceptance", "", "| seed | target sigma drop: suggested / standard | 2x | moment errors after "
          "flight N: suggested vs standard (%) | lower | inside limits |", "|---|---|---|---|---|---|"]
    for p in acc["per_seed"]:
        me = ", ".join(f"{c} {p['moment_errors_suggested'][c]:.1f} vs {p['moment_errors_standard'][c]:.1f}"
                       for c in MOMENT_COEFFICIENTS) if "moment_errors_suggested" in p else "-"
        drop = (f"{p['sigma_drop_suggested']:.2e} / {p['sigma_drop_standard']:.2e}" if "sigma_drop_suggested" in p
                else "-")
        L.append(f"| {p['seed']} | {drop} | {p.get('sigma_2x', '-')} | {me} | {p.get('moments_better', '-')} | "
                 f"{p['inside_limits']} |")
    L += ["", f"All seeds: sigma 2x {acc['sigma_2x_all']}, moments lower {acc['moments_better_all']}, designed inside "
              f"limits {acc['inside_limits_all']}, flown inside limits {acc['flown_inside_limits_all']}.", ""]
    for run in doc["runs"]:
        L += [f"## Seed {run['seed']}", ""]
        if run["target"]:
            L += [f"Target of the first suggestion: {run['target']['coefficient']} ({run['target']['fix']}; "
                  f"{run['target']['region'].get('description', '')}).", ""]
        for arm in ("suggested", "standard"):
            L += [f"### {arm}", "", "| flight | " + " | ".join(f"{c} err %" for c in COEFFICIENTS) + " | "
                  + " | ".join(f"{c} sigma" for c in MOMENT_COEFFICIENTS) + " | flown |",
                  "|" + "---|" * (len(COEFFICIENTS) + len(MOMENT_COEFFICIENTS) + 2)]
            for row in run["arms"][arm]:
                fl = "; ".join(f"#{f['rank']} {f['kind']} {'+'.join(f['controls'])} @ {f['V']:.0f} m/s"
                               for f in row.get("flown", [])) or row["kind"]
                L.append(f"| {row['flight']} | " + " | ".join(f"{row['errors_pct'][c]:.1f}" for c in COEFFICIENTS)
                         + " | " + " | ".join(f"{row['sigma'].get(c, float('nan')):.2e}" for c in MOMENT_COEFFICIENTS)
                         + f" | {fl} |")
            L.append("")
        if run["violations"]:
            L += ["Designed peaks outside the limits:", ""] + [f"- {v}" for v in run["violations"]] + [""]
        if run.get("flown_outside"):
            L += (["Flown (simulated, autopilot included) outside the limits:", ""]
                  + [f"- {v}" for v in run["flown_outside"]] + [""])
    return "\n".join(L) + "\n"


def campaign_figure(doc: dict) -> bytes:
    """PNG: held-out error vs truth (top) and mean sigma in the flagged regions (bottom) of Cl Cm Cn per flight."""
    import io

    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 5.5))
    axes = fig.subplots(2, 3, sharex=True)
    for j, c in enumerate(MOMENT_COEFFICIENTS):
        for run in doc["runs"]:
            for arm, style in (("suggested", "-o"), ("standard", "--s")):
                rows = run["arms"][arm]
                x = [r["flight"] for r in rows]
                axes[0, j].plot(x, [r["errors_pct"][c] for r in rows], style, ms=3, lw=1,
                                color="C0" if arm == "suggested" else "C1",
                                label=arm if run is doc["runs"][0] else None)
                axes[1, j].plot(x, [r["sigma"].get(c, np.nan) for r in rows], style, ms=3, lw=1,
                                color="C0" if arm == "suggested" else "C1")
        axes[0, j].set_title(c, fontsize=10)
        axes[1, j].set_xlabel("flight")
        for a in axes[:, j]:
            a.grid(alpha=0.3)
    axes[0, 0].set_ylabel("held-out error vs truth (%)")
    axes[1, 0].set_ylabel("mean sigma, flagged regions")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    return buf.getvalue()

