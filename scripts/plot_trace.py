#!/usr/bin/python3
"""Draws a trace CSV of scripts/trace.sh to a PNG: one panel per TPCTL point, temperature (PV,
and SP dashed) on the left axis, output on the right: OR as % of 16383 (faint: every sample;
solid: mean of the last 30 s, since the derivative makes OR jump with every 0.1° of reading)
and the Y duty the plant measured (mean of 8 s).

Usage: plot_trace.py TRACE.csv [OUT.png]      (needs Debian's python3-matplotlib)
"""

import csv
import math
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    src = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else re.sub(r"\.csv$", "", src) + ".png"
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_trace: {src} has no samples")
    channels = sorted({int(m.group(1)) for k in rows[0] for m in [re.match(r"c(\d+)_pv$", k)] if m})

    def col(name):
        return [float(r[name]) if r[name] != "" else math.nan for r in rows]

    times = col("time_s")
    minutes = [t / 60 for t in times]
    step = times[1] - times[0] if len(times) > 1 else 1.0
    window = max(1, round(30 / step))

    def running_mean(v):
        out, acc = [], 0.0
        for i, x in enumerate(v):
            acc += x
            if i >= window:
                acc -= v[i - window]
            out.append(acc / min(i + 1, window))
        return out

    n = len(channels)
    ncols = 2 if n > 1 else 1
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(7 * ncols, 2.6 * nrows), sharex=True,
                             squeeze=False)
    for k, c in enumerate(channels):
        ax = axes[k // ncols][k % ncols]
        pv, sp = col(f"c{c}_pv"), col(f"c{c}_sp")
        out_pct = [v / 16383 * 100 for v in col(f"c{c}_or")]
        duty = col(f"c{c}_duty")
        ax.plot(minutes, pv, color="tab:red", label="PV")
        ax.plot(minutes, sp, color="black", linestyle="--", linewidth=1, label="SP")
        ax.set_ylabel("°C")
        ax.set_title(f"channel {c}", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax2 = ax.twinx()
        ax2.plot(minutes, out_pct, color="tab:blue", linewidth=0.5, alpha=0.15)
        ax2.plot(minutes, running_mean(out_pct), color="tab:blue", linewidth=1,
                 label="OR % (30 s mean)")
        ax2.plot(minutes, duty, color="tab:green", linewidth=0.8, label="Y duty % (8 s mean)")
        ax2.set_ylim(-5, 105)
        ax2.set_ylabel("%")
        if k == 0:
            lines = [x for x in ax.get_lines() + ax2.get_lines()
                     if not x.get_label().startswith("_")]
            ax.legend(lines, [x.get_label() for x in lines], loc="lower right", fontsize=7)
    for k in range(n, nrows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("simulated minutes")
    fig.suptitle(f"{src}: {n} TPCTL point(s)")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print(f"plot_trace: {out}")


if __name__ == "__main__":
    main()
