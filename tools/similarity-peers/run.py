"""Raylab's similarity engine beside Dolos and copydetect on the same synthetic classes.

Usage (docs/GRADING.md, "Copied solutions"):
    cargo run -q -p xtask -- similarity-export --out DATA --classes 3
    python3 -m venv VENV && VENV/bin/pip install copydetect
    npm install @dodona/dolos-lib            # in this folder (this registry has no CLI package)
    VENV/bin/python tools/similarity-peers/run.py DATA

Each peer is run twice, as its documentation advises: on the region texts only, and on whole
files, with the starter as boilerplate both times (copydetect's -b, its other options at their
defaults; Dolos's -i, and -M 0.5). Printed: each tool's average precision over every pair of
every class, a pair sharing 2 or more regions a positive (the definition of
`raylab_grade::instructor::similarity::measure::average_precision`), and over the copiers' pairs
against the pairs sharing no region (the others left out).
"""
import csv
import os
import subprocess
import sys

from copydetect import CopyDetector

HERE = os.path.dirname(os.path.abspath(__file__))


def average_precision(scores, labels):
    """Mean over positives of the precision at their score, ties ranked together."""
    ranked = sorted(zip(scores, labels), key=lambda p: -p[0])
    positives = sum(labels)
    seen = hits = 0
    total = 0.0
    i = 0
    while i < len(ranked):
        j = i
        while j < len(ranked) and ranked[j][0] == ranked[i][0]:
            j += 1
        tie_hits = sum(1 for _, l in ranked[i:j] if l)
        seen += j - i
        hits += tie_hits
        total += tie_hits * hits / seen
        i = j
    return total / positives if positives else 0.0


def copydetect_scores(folder, template):
    detector = CopyDetector(test_dirs=[folder], boilerplate_dirs=[os.path.dirname(template)],
                            extensions=["rs"], silent=True, autoopen=False)
    detector.run()
    files = detector.test_files
    number = lambda f: int("".join(c for c in os.path.basename(f) if c.isdigit()))
    scores = {}
    for i, fi in enumerate(files):
        for j, fj in enumerate(files):
            if i < j:
                a, b = sorted((number(fi), number(fj)))
                # copydetect's pair similarity: the larger of the two files' copied shares.
                scores[(a, b)] = max(detector.similarity_matrix[i, j, 0], detector.similarity_matrix[j, i, 0])
    return scores


def dolos_scores(folder, template):
    out = subprocess.run(["node", os.path.join(HERE, "dolos.mjs"), folder, template],
                         check=True, capture_output=True, text=True, cwd=HERE).stdout
    scores = {}
    for line in out.splitlines():
        a, b, s = line.split(",")
        scores[(int(a), int(b))] = float(s)
    return scores


def main(data):
    rows = {}
    for cls in sorted(d for d in os.listdir(data) if d.startswith("class-")):
        labels = list(csv.DictReader(open(os.path.join(data, cls, "labels.csv"))))
        keys = [(int(r["a"]), int(r["b"])) for r in labels]
        truth = [int(r["shared"]) >= 2 for r in labels]
        # The second reading: copiers against pairs sharing nothing (the rest left out).
        copier = [r["copied"] == "true" for r in labels]
        kept = [c or int(r["shared"]) == 0 for c, r in zip(copier, labels)]
        results = {"raylab (regions)": {k: float(r["raylab"]) for k, r in zip(keys, labels)}}
        for form in ["regions", "whole"]:
            folder = os.path.join(data, cls, form)
            template = os.path.join(data, f"template-{form}", "starter.rs")
            results[f"copydetect ({form})"] = copydetect_scores(folder, template)
            results[f"Dolos ({form})"] = dolos_scores(folder, template)
        for tool, scores in results.items():
            rows.setdefault(tool, []).append(([scores.get(k, 0.0) for k in keys], truth, copier, kept))
    print("| tool | sharing 2+ regions vs the rest | copiers vs sharing nothing |\n|---|---:|---:|")
    for tool, classes in rows.items():
        scores = [s for c in classes for s in c[0]]
        truth = [t for c in classes for t in c[1]]
        copier = [(s, t) for c in classes for s, t, k in zip(c[0], c[2], c[3]) if k]
        copier_ap = average_precision([s for s, _ in copier], [t for _, t in copier])
        print(f"| {tool} | {average_precision(scores, truth):.3f} | {copier_ap:.3f} |")


if __name__ == "__main__":
    main(sys.argv[1])
