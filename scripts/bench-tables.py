#!/usr/bin/env python3
"""The bench's tables for the README and docs/which-strategy-wins.md, from docs/bench/<scene>/bench.{csv,md}:
per scene, every strategy at the largest budget with its relMSE and both efficiencies relative to the best mean
(95% intervals over the seeds), then the bench's verdicts. Writes docs/bench/summary.md."""
import csv
import pathlib
import re

SCENES = ["cornell-box", "near-light", "veach-mis", "occluded-light", "default"]
root = pathlib.Path(__file__).resolve().parent.parent / "docs" / "bench"


def num(s):
    return float(s) if s not in ("", None) else None


def rel(value, lo, hi, best):
    if value is None:
        return "—"
    lo_s = f"{lo / best:.3g}" if lo is not None else "0"
    hi_s = f"{hi / best:.3g}" if hi is not None else "∞"
    v = f"{value / best:.3g}"
    if value == best:
        v = f"**{v}**"
    return f"{v} [{lo_s}, {hi_s}]"


out = []
for scene in SCENES:
    md = (root / scene / "bench.md").read_text()
    rows = list(csv.DictReader(open(root / scene / "bench.csv")))
    spp = max(int(r["spp"]) for r in rows)
    rows = [r for r in rows if int(r["spp"]) == spp]
    heading = md.splitlines()[0].lstrip("# ")
    measured = re.search(r"(\d+) of (\d+) pixels", md)
    machine = re.search(r"Machine: ([^.]*)\.", md).group(1)
    out.append(f"#### {heading}, {spp} spp\n")
    out.append(
        f"{machine}; {rows[0]['seeds']} seeds; fixed primary hits; {measured.group(1)} of {measured.group(2)} "
        "pixels (those that see a light) left out; the reference's noise subtracted. Efficiencies relative to the "
        "best mean (bold = 1), with 95% intervals.\n"
    )
    out.append("| strategy | seconds | RMSE | relMSE | efficiency by MSE | by relMSE |")
    out.append("|---|---:|---:|---:|---:|---:|")
    best_e = max(num(r["efficiency"]) or 0 for r in rows)
    best_r = max(num(r["rel_efficiency"]) or 0 for r in rows)
    for r in rows:
        e = rel(num(r["efficiency"]), num(r["efficiency_lo"]), num(r["efficiency_hi"]), best_e)
        re_ = rel(num(r["rel_efficiency"]), num(r["rel_efficiency_lo"]), num(r["rel_efficiency_hi"]), best_r)
        out.append(
            f"| {r['strategy']} | {float(r['seconds']):.2f} | {float(r['rmse']):.3g} | {float(r['rel_mse']):.3g} "
            f"| {e} | {re_} |"
        )
    out.append("")
    out.extend(line for line in md.splitlines() if line.startswith("By "))
    out.append("")
(root / "summary.md").write_text("\n".join(out))
print((root / "summary.md").read_text())
