#!/usr/bin/python3
"""Plots of thermotwin's CSV outputs, written as PNG.

Run with /usr/bin/python3 (Debian's, which has matplotlib). Subcommands:

  plot.py temperatures CSV OUT.png --columns T02_degC,T10_degC [--rise-from-first] [--title T]
      temperatures (or their rise over the first row) against time in minutes, like the
      temperature-rise curves of a warm-up run.
  plot.py thermal_error CSV OUT.png --columns dy_um,dz_um [--title T]
      thermal displacement at the tool centre point in um against time in minutes.
  plot.py lines CSV OUT.png --x time_s --columns a,b [--xlabel X] [--ylabel Y] [--title T]
      any columns against any column.
  plot.py bars CSV OUT.png --label id --value mi_bits_dy [--top N] [--sort] [--title T]
      one bar per row, labelled by a (possibly text) column.
  plot.py residuals CSV OUT.png --effect-out EFFECT.png
      calibrate's residuals.csv (run, channel, unit, time_s, before, after, effect): per test run
      the residual before (solid) and after (dashed) per channel, K and um apart; and the
      identified effect (after - before) on the first test run.

The time column (--time, default time_s) is in seconds. The PNG is written to a temporary name and
renamed, so a failed run never leaves a partial image. Exit status 0 on success, 2 on bad input.
"""

import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)


class InputError(Exception):
    """Bad command-line input or CSV content; reported without a traceback."""


def read_table(path):
    """The CSV at `path` as (header, rows of text cells); '#' lines and blank lines skipped."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            lines = [
                (number, line)
                for number, line in enumerate(f, start=1)
                if line.strip() and not line.lstrip().startswith("#")
            ]
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror}")
    if not lines:
        raise InputError(f"{path}: no header line: expected column names such as time_s,T02_degC")
    parsed = list(csv.reader(line for _, line in lines))
    header = [name.strip() for name in parsed[0]]
    rows = []
    for (number, _), cells in zip(lines[1:], parsed[1:]):
        if len(cells) != len(header):
            raise InputError(
                f"{path}:{number}: row has {len(cells)} cells: expected {len(header)}"
            )
        rows.append((number, [cell.strip() for cell in cells]))
    return header, rows


def text_column(path, header, rows, name):
    if name not in header:
        raise InputError(f"{path}: no column '{name}'; columns are: {', '.join(header)}")
    index = header.index(name)
    return [cells[index] for _, cells in rows]


def numeric_column(path, header, rows, name):
    values = []
    index = header.index(name) if name in header else None
    if index is None:
        raise InputError(f"{path}: no column '{name}'; columns are: {', '.join(header)}")
    for number, cells in rows:
        try:
            values.append(float(cells[index]))
        except ValueError:
            raise InputError(
                f"{path}:{number}: column {index + 1} ({name}) = '{cells[index]}': "
                "expected a number"
            )
    return values


def column_names(text):
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise InputError(f"--columns '{text}': expected comma-separated column names")
    return names


def display_name(column):
    """`T02_degC` -> `T02`: the legend shows the quantity, the axis the unit."""
    for suffix in ("_degC", "_K", "_um", "_mm", "_m", "_s", "_Pa"):
        if column.endswith(suffix):
            return column[: -len(suffix)]
    return column


def save_atomically(figure, out):
    tmp = out + ".tmp"
    try:
        figure.savefig(tmp, format="png", dpi=150, bbox_inches="tight")
        os.replace(tmp, out)
    except OSError as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise InputError(f"{out}: cannot write the plot: {e.strerror}")
    finally:
        plt.close(figure)


def time_series_figure(args, columns, transform, ylabel):
    header, rows = read_table(args.csv)
    if not rows:
        raise InputError(f"{args.csv}: no data rows")
    minutes = [t / 60.0 for t in numeric_column(args.csv, header, rows, args.time)]
    figure, axes = plt.subplots(figsize=(7, 4.5))
    for column in columns:
        values = transform(numeric_column(args.csv, header, rows, column))
        axes.plot(minutes, values, label=display_name(column))
    axes.set_xlabel("Time [min]")
    axes.set_ylabel(ylabel)
    axes.grid(True, alpha=0.3)
    axes.legend()
    if args.title:
        axes.set_title(args.title)
    return figure


def plot_temperatures(args):
    columns = column_names(args.columns)
    if args.rise_from_first:
        figure = time_series_figure(
            args, columns, lambda v: [x - v[0] for x in v], "Temperature rise [K]"
        )
    else:
        figure = time_series_figure(args, columns, lambda v: v, "Temperature [°C]")
    save_atomically(figure, args.out)


def plot_thermal_error(args):
    figure = time_series_figure(
        args, column_names(args.columns), lambda v: v, "Thermal error [µm]"
    )
    save_atomically(figure, args.out)


def plot_lines(args):
    header, rows = read_table(args.csv)
    if not rows:
        raise InputError(f"{args.csv}: no data rows")
    x = numeric_column(args.csv, header, rows, args.x)
    figure, axes = plt.subplots(figsize=(7, 4.5))
    for column in column_names(args.columns):
        axes.plot(x, numeric_column(args.csv, header, rows, column), label=column)
    axes.set_xlabel(args.xlabel or args.x)
    if args.ylabel:
        axes.set_ylabel(args.ylabel)
    axes.grid(True, alpha=0.3)
    axes.legend()
    if args.title:
        axes.set_title(args.title)
    save_atomically(figure, args.out)


def plot_bars(args):
    header, rows = read_table(args.csv)
    if not rows:
        raise InputError(f"{args.csv}: no data rows")
    labels = text_column(args.csv, header, rows, args.label)
    values = numeric_column(args.csv, header, rows, args.value)
    pairs = list(zip(labels, values))
    if args.sort:
        pairs.sort(key=lambda pair: pair[1], reverse=True)
    if args.top is not None:
        if args.top < 1:
            raise InputError(f"--top {args.top}: expected at least 1")
        pairs = pairs[: args.top]
    figure, axes = plt.subplots(figsize=(max(5.0, 0.35 * len(pairs) + 2.0), 4.5))
    axes.bar(range(len(pairs)), [v for _, v in pairs])
    axes.set_xticks(range(len(pairs)))
    axes.set_xticklabels([label for label, _ in pairs], rotation=60, ha="right")
    axes.set_xlabel(args.label)
    axes.set_ylabel(args.ylabel or args.value)
    axes.grid(True, axis="y", alpha=0.3)
    if args.title:
        axes.set_title(args.title)
    save_atomically(figure, args.out)


def plot_residuals(args):
    header, rows = read_table(args.csv)
    if not rows:
        raise InputError(f"{args.csv}: no data rows")
    runs_col = text_column(args.csv, header, rows, "run")
    chans_col = text_column(args.csv, header, rows, "channel")
    units_col = text_column(args.csv, header, rows, "unit")
    hours = [t / 3600.0 for t in numeric_column(args.csv, header, rows, "time_s")]
    values = {k: numeric_column(args.csv, header, rows, k) for k in ("before", "after", "effect")}
    runs = sorted(set(runs_col))
    channels = sorted(set(zip(units_col, chans_col)))

    def series(run, channel, unit, key):
        picked = [
            (hours[i], values[key][i])
            for i in range(len(rows))
            if runs_col[i] == run and chans_col[i] == channel and units_col[i] == unit
        ]
        return [t for t, _ in picked], [v for _, v in picked]

    figure, axes = plt.subplots(2, len(runs), figsize=(6 * len(runs), 7), squeeze=False)
    for j, run in enumerate(runs):
        for i, unit in enumerate(["K", "um"]):
            ax = axes[i][j]
            for u, channel in channels:
                if u != unit:
                    continue
                t, before = series(run, channel, unit, "before")
                if not t:
                    continue
                (line,) = ax.plot(t, before, lw=0.8, alpha=0.6)
                ax.plot(t, series(run, channel, unit, "after")[1], lw=1.4, ls="--",
                        color=line.get_color())
            ax.set_title(f"{run}: residual [{unit}] (solid before, dashed after)")
            ax.set_xlabel("Time [h]")
    save_atomically(figure, args.out)
    figure, axes = plt.subplots(1, 2, figsize=(12, 4))
    for i, unit in enumerate(["K", "um"]):
        for u, channel in channels:
            if u != unit:
                continue
            t, effect = series(runs[0], channel, unit, "effect")
            if t:
                axes[i].plot(t, effect, label=channel)
        axes[i].set_title(f"identified effect on {runs[0]} [{unit}]")
        axes[i].set_xlabel("Time [h]")
    axes[1].legend(fontsize=7)
    save_atomically(figure, args.effect_out)


def parser():
    root = argparse.ArgumentParser(description="Plot thermotwin CSV outputs as PNG.")
    commands = root.add_subparsers(dest="command", required=True)

    def command(name, help_text, handler):
        sub = commands.add_parser(name, help=help_text)
        sub.add_argument("csv", help="input CSV with a header line")
        sub.add_argument("out", help="output PNG")
        sub.add_argument("--title", default="")
        sub.set_defaults(handler=handler)
        return sub

    temperatures = command("temperatures", "temperatures against time", plot_temperatures)
    temperatures.add_argument("--columns", required=True, help="e.g. T02_degC,T10_degC")
    temperatures.add_argument("--time", default="time_s", help="time column [s]")
    temperatures.add_argument(
        "--rise-from-first", action="store_true", help="plot the rise over the first row [K]"
    )

    error = command("thermal_error", "thermal error against time", plot_thermal_error)
    error.add_argument("--columns", required=True, help="e.g. dy_um,dz_um")
    error.add_argument("--time", default="time_s", help="time column [s]")

    lines = command("lines", "columns against a column", plot_lines)
    lines.add_argument("--x", required=True, help="column on the horizontal axis")
    lines.add_argument("--columns", required=True, help="comma-separated columns to plot")
    lines.add_argument("--xlabel", default="")
    lines.add_argument("--ylabel", default="")

    bars = command("bars", "one bar per row", plot_bars)
    bars.add_argument("--label", required=True, help="column naming each bar (text allowed)")
    bars.add_argument("--value", required=True, help="numeric column giving each bar's height")
    bars.add_argument("--ylabel", default="")
    bars.add_argument("--sort", action="store_true", help="largest first")
    bars.add_argument("--top", type=int, default=None, help="keep only the first N bars")

    residuals = command("residuals", "calibrate's residuals before and after", plot_residuals)
    residuals.add_argument("--effect-out", required=True, help="PNG of the identified effect")
    return root


def main(argv):
    args = parser().parse_args(argv)
    try:
        args.handler(args)
    except InputError as e:
        print(f"plot.py: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
