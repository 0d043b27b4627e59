#!/usr/bin/python3
"""Draws a trace CSV of scripts/trace.sh to a PNG: one panel per TPCTL point, temperature (PV,
and SP dashed) on the left axis, output on the right: OR as % of 16383 (faint: every sample;
solid: mean of the last 30 s, since the derivative makes OR jump with every 0.1° of reading)
and the Y duty the plant measured (mean of 8 s).

One row of two panels per PID loop (pid<k>_* columns): on the left the first 5 minutes in
seconds, PV and SV (dashed) in °C and MV (D, output counts) on the right axis, auto-tuning
shaded and its end marked with the gains it wrote (Kp %, TI × 100 ms, TD × 10 ms); on the
right the whole run in minutes, PV within SV ± 2 °C.

A temperature register reads 0 until its module's first conversion, which comes after the
trace's first sample: a PV column's leading zeros are not drawn (the curve starts at the first
reading, not with a jump from 0 °C).

Usage: plot_trace.py TRACE.csv [OUT.png]      (needs Debian's python3-matplotlib:
                                               scripts/install-deps.sh plot)
"""

import csv
import math
import re
import sys

try:
    import matplotlib
except ImportError:
    print("plot_trace: needs matplotlib: install Debian's python3-matplotlib "
          "(scripts/install-deps.sh plot)", file=sys.stderr)
    sys.exit(2)

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
    fig = draw(rows, src)
    fig.savefig(out, dpi=90)
    print(f"plot_trace: {out}")


def measured(values):
    """A PV column without the samples before the first conversion (the register reads 0 until
    then): its leading zeros become NaN, unless the column is 0 throughout."""
    first = next((i for i, x in enumerate(values) if x != 0), None)
    if first is None:
        return list(values)
    return [math.nan] * first + list(values[first:])


def draw(rows, src):
    """The figure of a trace's rows (csv.DictReader's); src names it in the title."""
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

    loops = sorted({int(m.group(1)) for k in rows[0] for m in [re.match(r"pid(\d+)_pv$", k)] if m})
    n = len(channels)
    ncols = 2 if n > 1 or loops else 1
    crows = math.ceil(n / ncols)
    nrows = crows + len(loops)
    fig, axes = plt.subplots(nrows, ncols, figsize=(7 * ncols, 2.6 * crows + 3.2 * len(loops)),
                             squeeze=False)
    for k, c in enumerate(channels):
        ax = axes[k // ncols][k % ncols]
        if k >= ncols:
            ax.sharex(axes[0][k % ncols])
        pv, sp = measured(col(f"c{c}_pv")), col(f"c{c}_sp")
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
            legend = [x for x in ax.get_lines() + ax2.get_lines()
                      if not x.get_label().startswith("_")]
        if k >= n - ncols:
            ax.set_xlabel("simulated minutes")
    for k in range(n, crows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    for j, p in enumerate(loops):
        plot_pid(axes[crows + j], p, col, times)
    title = []
    if n:
        title.append(f"{n} TPCTL point(s)")
    if loops:
        title.append(f"{len(loops)} PID loop(s)")
    height = fig.get_figheight()
    fig.suptitle(f"{src}: {', '.join(title)}", y=1 - 0.1 / height, va="top")
    top = 1 - 0.45 / height
    if n:
        # The channels' legend goes above the panels, under the title: inside a panel it would
        # hide that panel's curves.
        fig.legend(legend, [x.get_label() for x in legend], loc="upper center", ncol=4,
                   fontsize=8, bbox_to_anchor=(0.5, top), frameon=False)
        top -= 0.3 / height
    fig.tight_layout(rect=(0, 0, 1, top))
    return fig


def plot_pid(axes, p, col, times):
    """PID loop p on a row of two panels: the first 5 minutes, then the whole run."""
    pv, sv, mv, at = (measured(col(f"pid{p}_pv")), col(f"pid{p}_sv"), col(f"pid{p}_mv"),
                      col(f"pid{p}_at"))
    kp, ti, td = col(f"pid{p}_kp"), col(f"pid{p}_ti"), col(f"pid{p}_td")
    # Auto-tuning: the samples with S3+1 b4 ON; it ended at the first sample after them.
    tuning = [i for i, x in enumerate(at) if x == 1]
    end = tuning[-1] + 1 if tuning and tuning[-1] + 1 < len(times) else None
    first = [i for i, t in enumerate(times) if t <= 300]
    ax = axes[0]
    ax.plot([times[i] for i in first], [pv[i] for i in first], color="tab:red", label="PV")
    ax.plot([times[i] for i in first], [sv[i] for i in first], color="black", linestyle="--",
            linewidth=1, label="SV")
    ax.set_xlabel("simulated s")
    ax.set_ylabel("°C")
    ax.grid(True, alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot([times[i] for i in first], [mv[i] for i in first], color="tab:blue", linewidth=0.8,
             label="MV (D)")
    ax2.set_ylabel("MV")
    if tuning:
        ax.axvspan(times[tuning[0]], times[end] if end else times[-1], color="tab:orange",
                   alpha=0.12, label="auto-tuning")
    if end:
        ax.axvline(times[end], color="tab:orange", linewidth=1)
        ax.annotate(f"AT ends {times[end]:g} s\nKp {kp[end]:g} %, TI {ti[end]:g}, TD {td[end]:g}",
                    (times[end], 0.36), xycoords=("data", "axes fraction"), xytext=(4, 0),
                    textcoords="offset points", fontsize=7)
    ax.set_title(f"PID {p}: auto-tuning and the tuned loop, first 5 minutes", fontsize=10)
    lines = [x for x in ax.get_lines() + ax2.get_lines() + ax.patches
             if not x.get_label().startswith("_")]
    # Headroom above the curves for the legend.
    top = max([x for x in pv + sv if not math.isnan(x)], default=1.0)
    ax.set_ylim(min(0.0, min([x for x in pv if not math.isnan(x)], default=0.0)), top * 1.3)
    ax2.set_ylim(min(0.0, min(mv, default=0.0)), max(mv, default=1.0) * 1.3 or 1.0)
    ax.legend(lines, [x.get_label() for x in lines], loc="upper right", fontsize=7, ncol=4)

    ax = axes[1]
    minutes = [t / 60 for t in times]
    ax.plot(minutes, pv, color="tab:red", linewidth=0.8, label="PV")
    ax.plot(minutes, sv, color="black", linestyle="--", linewidth=1, label="SV")
    target = sv[-1]
    if not math.isnan(target):
        ax.set_ylim(target - 2, target + 2)
    if end:
        ax.axvline(minutes[end], color="tab:orange", linewidth=1)
    ax.set_xlabel("simulated minutes")
    ax.set_ylabel("°C")
    ax.grid(True, alpha=0.3)
    ax.set_title(f"PID {p}: the whole run, SV ± 2 °C", fontsize=10)
    ax.legend(loc="lower right", fontsize=7)


if __name__ == "__main__":
    main()
