#!/usr/bin/env python3
"""Plot error against render time from `vkrt render --report` CSV files.

    tools/plot_convergence.py conv1.csv [conv2.csv ...] -o plot.png [--metric relmse]
        [--label NAME ...] [--estimated]

One line per file on log-log axes: the true error (columns rmse/relmse/mape,
present when the report had --reference) or, with --estimated or when there is
no reference, the estimate from the render's own variance (est_rmse,
est_relmse). The x axis is render seconds (start-up excluded; it is printed in
each file's header). Needs matplotlib (Debian: python3-matplotlib).
"""
import argparse
import csv
import math
import sys


def read_report(path):
    header = ""
    rows = []
    with open(path, newline="") as f:
        lines = []
        for line in f:
            if line.startswith("#"):
                header = line[1:].strip()
            elif line.strip():
                lines.append(line)
    for row in csv.DictReader(lines):
        rows.append({k: float(v) for k, v in row.items()})
    if not rows:
        raise SystemExit(f"plot_convergence: {path}: no data rows")
    return header, rows


def column_for(rows, metric, estimated):
    true_name, est_name = metric, "est_" + metric
    if not estimated and true_name in rows[0]:
        return true_name
    if est_name in rows[0]:
        return est_name
    raise SystemExit(f"plot_convergence: no column '{true_name}' or '{est_name}' (mape needs a reference)")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("reports", nargs="+", help="CSV files from vkrt render --report")
    parser.add_argument("-o", "--output", required=True, help="image to write (PNG, PDF, SVG)")
    parser.add_argument("--metric", choices=["rmse", "relmse", "mape"], default="relmse")
    parser.add_argument("--label", action="append", help="label per report (default: file name)")
    parser.add_argument("--estimated", action="store_true", help="plot the variance-based estimate")
    args = parser.parse_args()
    if args.label and len(args.label) != len(args.reports):
        parser.error("give one --label per report")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_convergence: matplotlib is missing: apt-get install python3-matplotlib "
                 "(and run /usr/bin/python3 tools/plot_convergence.py), or pip install matplotlib")

    fig, ax = plt.subplots(figsize=(7, 5))
    for i, path in enumerate(args.reports):
        _, rows = read_report(path)
        name = column_for(rows, args.metric, args.estimated)
        points = [(r["seconds"], r[name]) for r in rows
                  if r["seconds"] > 0 and math.isfinite(r[name]) and r[name] > 0]
        if not points:
            raise SystemExit(f"plot_convergence: {path}: nothing positive and finite to plot in {name}")
        label = args.label[i] if args.label else path
        ax.loglog([p[0] for p in points], [p[1] for p in points], marker="o", label=f"{label} ({name})")
    ax.set_xlabel("render seconds (start-up excluded)")
    ax.set_ylabel(args.metric)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
