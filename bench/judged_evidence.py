#!/usr/bin/python3
"""How well each term of a pose's evidence separates right poses from wrong ones, from the poses the acceptance
judged (`generalisation_bench --judged FILE`, `recognize` with keep_judged).

  bench/judged_evidence.py JUDGED.jsonl [--by set|hypothesis|grey] [--model MODEL.json] [--verified VERIFIED.jsonl]
                           [--made-by TEXT] [--results FILE]

Prints, per term, the area under the ROC curve (AUC: the chance that a right pose has the higher value; 0.5 = no
separation, below 0.5 = lower is right) over every judged pose, and per group; the counts of right and wrong poses and
how the acceptance decided them; with --model (scripts/train_acceptance's), how that model would decide the same
poses; with --verified (`generalisation_bench --verified`, the same run), why the objects missed were missed: no right
pose verified at all, or one verified and beaten or below the bar. --made-by quotes how JUDGED was made in the report. With --results, the report replaces its section of that
file (bench/RESULTS.md).
"""

import argparse
import json
import math
import os
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_util import report  # noqa: E402

TERMS = ["score", "depth_agreement", "color_agreement", "edge_agreement", "surface_error", "contour_agreement",
         "continuation", "visible_fraction", "inlier_fraction", "explained_surface", "free_space_violation",
         "occluding_contour", "creased_contour"]


def auc(right, wrong):
    """P(a right value > a wrong one), ties counted half (Mann-Whitney U over sorted values)."""
    if not right or not wrong:
        return float("nan")
    values = sorted([(v, 1) for v in right] + [(v, 0) for v in wrong])
    rank_sum, i = 0.0, 0
    while i < len(values):
        j = i
        while j < len(values) and values[j][0] == values[i][0]:
            j += 1
        mean_rank = (i + 1 + j) / 2.0  # ranks i+1 .. j
        rank_sum += mean_rank * sum(1 for k in range(i, j) if values[k][1] == 1)
        i = j
    u = rank_sum - len(right) * (len(right) + 1) / 2.0
    return u / (len(right) * len(wrong))


def group_of(record, by):
    if by == "set":
        return record["set"]
    if by == "hypothesis":
        return record["hypothesis"]
    return "grey" if record["grey"] else "textured"


def table(records, by):
    groups = defaultdict(list)
    for record in records:
        groups["all"].append(record)
        groups[group_of(record, by)].append(record)
    names = ["all"] + sorted(g for g in groups if g != "all")
    lines = ["| term | " + " | ".join(names) + " |", "|---|" + "---:|" * len(names)]
    counts = []
    for name in names:
        right = sum(1 for r in groups[name] if r["right"])
        accepted_right = sum(1 for r in groups[name] if r["right"] and r["accepted"])
        accepted_wrong = sum(1 for r in groups[name] if not r["right"] and r["accepted"])
        counts.append("%d right (%d accepted), %d wrong (%d accepted)" %
                      (right, accepted_right, len(groups[name]) - right, accepted_wrong))
    lines.append("| poses | " + " | ".join(counts) + " |")
    for term in TERMS:
        cells = []
        for name in names:
            right = [r[term] for r in groups[name] if r["right"]]
            wrong = [r[term] for r in groups[name] if not r["right"]]
            cells.append("%.2f" % auc(right, wrong))
        lines.append("| %s | %s |" % (term, " | ".join(cells)))
    return "\n".join(lines) + "\n"


def model_verdicts(path, records):
    """Each record's verdict by the logistic model at `path` (scripts/train_acceptance), computed as it does."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts"))
    import importlib.machinery
    import importlib.util
    loader = importlib.machinery.SourceFileLoader("train_acceptance", os.path.join(sys.path[0], "train_acceptance"))
    spec = importlib.util.spec_from_loader("train_acceptance", loader)
    trainer = importlib.util.module_from_spec(spec)
    loader.exec_module(trainer)
    with open(path) as f:
        model = json.load(f)
    return [p >= model["threshold"] for p in trainer.probabilities(model, records)], model


def verdict_table(records, verdicts, model_path):
    frames = len({(r["run"], r["frame"]) for r in records})
    lines = ["| rule | right accepted | wrong accepted | wrong accepted per frame |", "|---|---:|---:|---:|"]
    for name, accepted in (("hand-set (score >= min score)", [r["accepted"] for r in records]),
                           ("`%s`" % model_path, verdicts)):
        right = sum(1 for r, a in zip(records, accepted) if a and r["right"])
        wrong = sum(1 for r, a in zip(records, accepted) if a and not r["right"])
        lines.append("| %s | %d of %d | %d | %.3f |" % (name, right, sum(1 for r in records if r["right"]), wrong,
                                                       wrong / max(frames, 1)))
    return "\n".join(lines) + "\n"


def missed_table(path):
    """Per set: objects, found, and the missed ones by cause, from a --verified file."""
    try:
        with open(path) as lines:
            objects = [json.loads(line) for line in lines if line.strip()]
    except (OSError, ValueError) as error:
        sys.exit("judged_evidence: %s: %s" % (path, error))
    sets = ["all"] + sorted({o["set"] for o in objects})
    lines = ["| set | objects | found | missed: no right pose verified | missed: a right one verified, a wrong one "
             "scored higher | missed: a right one verified, best of its model, below the bar |",
             "|---|---:|---:|---:|---:|---:|"]
    for name in sets:
        group = [o for o in objects if name == "all" or o["set"] == name]
        missed = [o for o in group if not o["found"]]
        none = sum(1 for o in missed if o["right"] == 0)
        beaten = sum(1 for o in missed if o["right"] > 0 and o["best_wrong_score"] > o["best_right_score"])
        lines.append("| %s | %d | %d | %d | %d | %d |" % (name, len(group), len(group) - len(missed), none, beaten,
                                                       len(missed) - none - beaten))
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("judged")
    parser.add_argument("--by", choices=["set", "hypothesis", "grey"], default="set")
    parser.add_argument("--model", help="a model of scripts/train_acceptance to decide the same poses")
    parser.add_argument("--verified", help="generalisation_bench --verified file of the same run")
    parser.add_argument("--made-by", help="the command that wrote JUDGED, quoted in the report")
    parser.add_argument("--results", help="markdown file whose section this report replaces")
    args = parser.parse_args()
    try:
        with open(args.judged) as lines:
            records = [json.loads(line) for line in lines if line.strip()]
    except (OSError, ValueError) as error:
        sys.exit("judged_evidence: %s: %s" % (args.judged, error))
    if not records:
        sys.exit("judged_evidence: %s holds no judged poses" % args.judged)
    lines = ["Area under the ROC curve of each term over the poses the acceptance judged (each model's best pose per "
             "frame; 1 = every right pose has the higher value, 0.5 = no separation, below 0.5 = lower is right), "
             "and how they were decided. Right: ADD (ADD-S for symmetric models) < 0.1 x diameter. %d poses of %d "
             "frames from `%s`%s." % (len(records), len({(r["run"], r["frame"]) for r in records}), args.judged,
                                      ", made by `%s`" % args.made_by if args.made_by else ""), "",
             table(records, args.by)]
    if args.model:
        verdicts, _ = model_verdicts(args.model, records)
        lines += ["The same poses decided by the hand-set rule and by the model (offline: under `--hypotheses both` "
                  "point pairs run for the models the context's pose was rejected for, so a run with the model "
                  "judges slightly different poses):", "", verdict_table(records, verdicts, args.model)]
    if args.verified:
        lines += ["Why the objects missed were missed (`%s`: every pose verified for each object present, right "
                  "when ADD (ADD-S) < 0.1 x diameter):" % args.verified, "", missed_table(args.verified)]
    if args.results:
        report(args.results, "Evidence of judged poses (judged_evidence.py)", lines)
    else:
        print("\n".join(lines))


if __name__ == "__main__":
    main()
