#!/usr/bin/python3
"""How well each term of a pose's evidence separates right poses from wrong ones, from the poses the acceptance
judged (`generalisation_bench --judged FILE`, `recognize` with keep_judged).

  bench/judged_evidence.py JUDGED.jsonl [--by set|hypothesis|grey]

Prints, per term, the area under the ROC curve (AUC: the chance that a right pose has the higher value; 0.5 = no
separation, below 0.5 = lower is right) over every judged pose, and per group; the counts of right and wrong poses and
how the acceptance decided them.
"""

import argparse
import json
import sys
from collections import defaultdict

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


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("judged")
    parser.add_argument("--by", choices=["set", "hypothesis", "grey"], default="set")
    args = parser.parse_args()
    try:
        with open(args.judged) as lines:
            records = [json.loads(line) for line in lines if line.strip()]
    except (OSError, ValueError) as error:
        sys.exit("judged_evidence: %s: %s" % (args.judged, error))
    if not records:
        sys.exit("judged_evidence: %s holds no judged poses" % args.judged)
    print(table(records, args.by))


if __name__ == "__main__":
    main()
