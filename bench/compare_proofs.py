#!/usr/bin/env python3
"""Before/after table of the certificate's proof (issue #12).

Reads two bench output directories (bench.csv and bench_stages.csv written by
build/bench/bench, one from the commit before the change and one after, run
in the same session) and prints a Markdown table: per dataset, SE-Sync's
proven relative bound, its verification stage time, Certify's time (the
after-the-fact check of SE-Sync's poses) and bound, and the arithmetic of
the proof after the change.

  bench/compare_proofs.py BEFORE_DIR AFTER_DIR [--out FILE.md]
"""

import argparse
import csv
import math
import os
import sys


def read_rows(directory):
    rows = {}
    with open(os.path.join(directory, "bench.csv")) as f:
        for row in csv.DictReader(f):
            rows[(row["dataset"], row["method"], row["init"])] = row
    stages = {}
    with open(os.path.join(directory, "bench_stages.csv")) as f:
        for row in csv.DictReader(f):
            if row["method"] == "SE-Sync":
                stages[row["dataset"]] = row
    return rows, stages


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def fmt(x, spec):
    return "" if math.isnan(x) else format(x, spec)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--out")
    args = parser.parse_args()
    before_rows, before_stages = read_rows(args.before)
    after_rows, after_stages = read_rows(args.after)
    datasets = sorted(after_stages, key=str.lower)
    lines = [
        "| dataset | rel. bound before (first-order) | rel. bound after "
        "(complete) | proof after (double+dd factorizations, dd time) | "
        "verify before [s] | verify after [s] | after / before | "
        "Certify before [s] | Certify after [s] | after / before | "
        "Certify bound after |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    verify_ratios, certify_ratios = [], []
    for dataset in datasets:
        b_solve = before_rows.get((dataset, "SE-Sync", "chordal"), {})
        a_solve = after_rows.get((dataset, "SE-Sync", "chordal"), {})
        b_cert = before_rows.get((dataset, "Certify", "sesync"), {})
        a_cert = after_rows.get((dataset, "Certify", "sesync"), {})
        b_stage = before_stages.get(dataset, {})
        a_stage = after_stages[dataset]
        bv = number(b_stage.get("verification_s"))
        av = number(a_stage.get("verification_s"))
        bc = number(b_cert.get("time_min_s"))
        ac = number(a_cert.get("time_min_s"))
        rv = av / bv if bv > 0 else math.nan
        rc = ac / bc if bc > 0 else math.nan
        if not math.isnan(rv):
            verify_ratios.append(rv)
        if not math.isnan(rc):
            certify_ratios.append(rc)
        lines.append(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |".format(
                dataset,
                fmt(number(b_solve.get("rel_subopt_bound")), ".1e"),
                fmt(number(a_solve.get("rel_subopt_bound")), ".1e"),
                a_solve.get("proof", ""),
                fmt(bv, ".4f"), fmt(av, ".4f"), fmt(rv, ".2f"),
                fmt(bc, ".4f"), fmt(ac, ".4f"), fmt(rc, ".2f"),
                fmt(number(a_cert.get("rel_subopt_bound")), ".1e")))

    def geomean(values):
        return math.exp(sum(map(math.log, values)) / len(values)) if values else math.nan

    lines.append("")
    lines.append(
        "Geometric mean of after / before: verification {}, Certify {} "
        "({} datasets).".format(fmt(geomean(verify_ratios), ".2f"),
                                fmt(geomean(certify_ratios), ".2f"),
                                len(datasets)))
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
