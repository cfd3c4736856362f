#!/usr/bin/env python3
"""Publishes issue 31's measurements (scripts/policy-search): reads the
report runs (OUT/evaluate.jsonl) and the searches' logs (OUT/*.search.json),
writes RESULTS (JSON) and renders the tables of DOC between its
`<!-- results:begin -->` and `<!-- results:end -->` lines from RESULTS.

    policy-search-publish.py OUT RESULTS DOC     publish and render
    policy-search-publish.py --check RESULTS DOC fail if DOC's tables are not RESULTS'
"""
import glob
import json
import math
import os
import re
import sys

BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"
# how the report names each controller
NAMES = {
    "oc": "orbital construction",
    "-oc.policy": "search from distilled OC",
    "-more.policy": "search from distilled OC, continued",
    "-again.policy": "search from distilled OC, continued twice",
    "-robust.policy": "search from distilled OC, continued at twice the noise",
    "letter-I-robust.policy": "search from Q-learning's table, at twice the noise",
    "annulus-random.policy": "search from random",
    "annulus-from-q.policy": "search from Q-learning's table",
    "annulus-q.policy": "Q-learning (distilled start, selection)",
    "annulus-q-decay.policy": "Q-learning, decaying exploration",
    "annulus-q-optimistic.policy": "Q-learning, optimistic start (Q 5)",
    "annulus-q-nstep.policy": "Q-learning, 4-step returns (distilled start, selection)",
    "annulus-q-nstep-optimistic.policy": "Q-learning, 4-step returns, optimistic start (Q 5)",
    "-q-nstep.policy": "Q-learning, 4-step returns (distilled start, selection)",
    "thesis-T-bits9.policy": "search from distilled OC, 9-bit state",
    "thesis-T-bits9-more.policy": "search from distilled OC, 9-bit state, continued",
    "thesis-T-bits9-again.policy": "search from distilled OC, 9-bit state, continued twice",
    "thesis-T-bits9-third.policy": "search from distilled OC, 9-bit state, continued three times",
    "thesis-T-bits9-wide.policy": "search from distilled OC, 9-bit state, continued twice, then with 12 candidates",
    "thesis-T-bits9-robust.policy": "search from distilled OC, 9-bit state, the 12-candidate table continued at the default noise and twice it",
    "thesis-T-bits9-twice.policy": "search from distilled OC, 9-bit state, the 12-candidate table continued at twice the noise",
    "thesis-T-bits9-twice-both.policy": "search from distilled OC, 9-bit state, the 12-candidate table continued at twice the noise, then at both",
    "thesis-T-bits9-both-more.policy": "search from distilled OC, 9-bit state, the 12-candidate table continued at twice the noise, then at both, twice",
    "thesis-T-bits9-both-twice.policy": "search from distilled OC, 9-bit state, the 12-candidate table continued at twice the noise, then at both, twice, then at twice the noise again",
    "letter-I-robust-three.policy": "search from Q-learning's table, at twice the noise, then at the default noise, twice and 2.5 times it",
    "letter-I-robust-both.policy": "search from Q-learning's table, at twice the noise, then at the default noise and twice it",
    "general.policy": "the general search (annulus, T, L, X), from distilled OC",
    "general-robust.policy": "the general search, continued at twice the noise",
    "general-robust-both.policy": "the general search, continued at twice the noise, then at the default noise and twice it",
    "general-robust-three.policy": "the general search, continued at twice the noise, then at the default noise and twice it, then 2.5 times it as well",
    "general-from-L.policy": "the general search from the L's table, at the default noise and twice it",
    "general-from-X.policy": "the general search from the X's table, at the default noise and twice it",
    "general-drawn.policy": "the general search, continued at twice the noise, then at both, then 2.5 times it as well, then on our drawn T, L and X as well, at both",
    "general-drawn-three.policy": "the general search, continued at twice the noise, then at both, then 2.5 times it as well, then on our drawn T, L and X as well, at both, then 2.5 times it as well",
    "general-from-drawn-X.policy": "the general search, on our drawn T, L and X as well, at both noises, from the table searched on our drawn X alone",
    "general-from-drawn-X-more.policy": "the general search, on our drawn T, L and X as well, at both noises, from the table searched on our drawn X alone, continued",
    "general-from-drawn-X-again.policy": "the general search, on our drawn T, L and X as well, at both noises, from the table searched on our drawn X alone, continued twice",
    "general-from-drawn-X-robust.policy": "the general search, on our drawn T, L and X as well, at both noises, from the table searched on our drawn X alone, continued twice, then 2.5 times the noise as well",
    "general-from-drawn-X-robust-more.policy": "the general search, on our drawn T, L and X as well, at both noises, from the table searched on our drawn X alone, continued twice, then 2.5 times the noise as well, twice",
    "general-turned.policy": "the general search, on our drawn T, L and X and our T and L turned or mirrored as well, at three noises, from the table searched on our drawn X alone, continued four times",
    "thesis-T-bits9-both-again.policy": "search from distilled OC, 9-bit state, the 12-candidate table continued at twice the noise, then at both, three times",
    "thesis-T-bits9-three.policy": "search from distilled OC, 9-bit state, the 12-candidate table continued at twice the noise, then at both, twice, then 2.5 times it as well",
    "thesis-T-obstacle.policy": "search from distilled OC, 10-bit state (robots seen)",
    "thesis-T-obstacle-more.policy": "search from distilled OC, 10-bit state (robots seen), continued",
}


def name_of(controller):
    if controller == "oc":
        return NAMES["oc"]
    base = os.path.basename(controller)
    ending = next((e for e in ("-again.policy", "-more.policy", "-robust.policy", "-q-nstep.policy") if base.endswith(e)), "-oc.policy")
    return NAMES.get(base) or NAMES[ending]


def evaluation(path):
    """An evaluation's lines by shape and controller name, with each
    controller's formations per million steps."""
    shapes = {}
    for r in (json.loads(l) for l in open(path) if l.strip()):
        shape = shapes.setdefault(r["field"], {})
        c = shape.setdefault(name_of(r["controller"]), {"policy": r["controller"], "seeds": [], "formations": []})
        c["seeds"].append(r["seed"])
        c["formations"].append(r["formations"])
        c["steps_per_seed"] = r["steps"]
    for shape in shapes.values():
        for c in shape.values():
            c["per_million"] = round(sum(c["formations"]) * 1e6 / (c["steps_per_seed"] * len(c["formations"])), 1)
    return shapes


def publish(out, results_path):
    shapes = evaluation(os.path.join(out, "evaluate.jsonl"))
    # the general tables at twice the noise (scripts/policy-search evaluate-2x)
    twice = os.path.join(out, "evaluate-2x.jsonl")
    shapes_2x = evaluation(twice) if os.path.exists(twice) else {}
    searches = []
    for path in sorted(glob.glob(os.path.join(out, "*.search.json"))):
        log = json.load(open(path))

        def f(s):
            return s["formations"] if isinstance(s, dict) else s

        searches.append({
            "name": os.path.basename(path)[: -len(".search.json")],
            # a general search's fields, the first the worlds' own
            "field": " + ".join([log["world"]["field"], *log["search"].get("also_field", [])]),
            "sensors": log["world"]["sensors"],
            # the noise levels it was scored at, the run's own first
            "noise": " + ".join(f"{n:g}" for n in [log["world"]["noise"], *log["search"].get("also_noise", [])]),
            "hasher": log["world"]["learn"]["hasher"],
            "start": log["search"]["start"],
            "generations": len(log["generations"]),
            "steps": log["steps"],
            "validation_worlds": len(log["validation_seeds"]),
            "validation_steps": log["search"]["validation_steps"],
            "start_validation": f(log["start_validation"]),
            "result_validation": f(log["result_validation"]),
        })
    results = {"command": "scripts/policy-search", "shapes": shapes, "shapes_2x": shapes_2x, "searches": searches}
    with open(results_path + ".tmp", "w") as fh:
        json.dump(results, fh, indent=1, sort_keys=True)
        fh.write("\n")
    os.replace(results_path + ".tmp", results_path)


def general_shapes(results):
    """The shapes the general tables are searched on: every general
    search's fields, as their logs name them, in order of first mention."""
    shapes = []
    for s in results["searches"]:
        if s["name"].startswith("general"):
            shapes += [f for f in s["field"].split(" + ") if f not in shapes]
    return shapes


def report_shapes():
    """The report's shapes, as sim::scenario::shape_pucks fixes them."""
    source = open(os.path.join(os.path.dirname(__file__), "../sim/src/scenario/shape_pucks.rs")).read()
    table = source.split("pub const TV_SHAPE_PUCKS", 1)[1].split("];", 1)[0]
    return re.findall(r'\("([^"]+)", \d+\)', table)


def run_of(controller):
    """The run a report controller's table came from (its file's stem)."""
    return os.path.basename(controller["policy"])[: -len(".policy")]


def is_general(controller):
    """Whether a report controller is a general table (runs named general*)."""
    return run_of(controller).startswith("general")


def own_counts(shape):
    """Per million steps of every table learned for the shape itself (each
    search, whatever its state, and Q-learning's): not OC, not a general
    table."""
    return [c["per_million"] for n, c in shape.items() if n != NAMES["oc"] and not is_general(c)]


def count_of(results, evaluation, field, run):
    """A run's controller on `field` in `evaluation` (`shapes` or
    `shapes_2x`), or None."""
    return next((c for c in results.get(evaluation, {}).get(field, {}).values() if run_of(c) == run), None)


def general_ranking(results, shapes, evaluation="shapes"):
    """The general tables (runs named general*) on `shapes`, best first by
    the search's own measure: the sum over the shapes of ln(1 +
    formations), here per million steps, in `evaluation` (`shapes` at the
    default noise, `shapes_2x` at twice it)."""
    runs = {}
    for field in shapes:
        for c in results.get(evaluation, {}).get(field, {}).values():
            if is_general(c):
                runs.setdefault(run_of(c), {})[field] = c["per_million"]
    ranked = []
    for run, counts in runs.items():
        if len(counts) == len(shapes):
            row = [counts[f] for f in shapes]
            ranked.append((run, row, sum(math.log1p(c) for c in row)))
    return sorted(ranked, key=lambda r: -r[2])


def tables(results):
    lines = ["| shape | controller | formations per million steps | / OC |", "|---|---|---:|---:|"]
    for field, shape in results["shapes"].items():
        oc = shape.get(NAMES["oc"], {}).get("per_million")
        for name, c in sorted(shape.items(), key=lambda kv: (kv[0] != NAMES["oc"], kv[0])):
            ratio = f"{c['per_million'] / oc:.2f}" if oc else "-"
            lines.append(f"| {field} | {name} | {c['per_million']:,.1f} | {ratio} |")
    lines += ["", "| target | figure | measured | met |", "|---|---|---:|---|"]
    annulus = results["shapes"].get("annulus", {})
    oc = annulus.get(NAMES["oc"], {}).get("per_million")
    learned = [(n, c["per_million"]) for n, c in annulus.items() if n != NAMES["oc"]]
    if oc and learned:
        n, best = max(learned, key=lambda nc: nc[1])
        lines.append(f"| annulus: a learned policy >= 1.15x OC | best ({n}) / OC | {best / oc:.3f} | {'yes' if best >= 1.15 * oc else 'no'} |")
    reported = report_shapes()
    for field, shape in results["shapes"].items():
        # the annulus' target is above; shapes only searched on have none
        if field == "annulus" or field not in reported:
            continue
        oc = shape.get(NAMES["oc"], {}).get("per_million", 0.0)
        # the general tables have their own tables below
        learned = own_counts(shape)
        if not learned:
            continue
        found = max(learned)
        need = 50.0
        if oc >= 20:
            need = max(need, oc)
        if field == "thesis:L":
            need = max(need, 1.5 * oc)
        lines.append(f"| {field}: >= {need:,.1f} per million | best learned / million steps | {found:,.1f} | {'yes' if found >= need else 'no'} |")
    shapes = general_shapes(results)
    ranked = general_ranking(results, shapes)
    if ranked:
        lines += ["", "| general table | " + " | ".join(shapes) + " | sum of ln(1 + per million) |",
                  "|---|" + "---:|" * (len(shapes) + 1)]
        for run, counts, measure in ranked:
            lines.append(f"| {run} | " + " | ".join(f"{c:,.1f}" for c in counts) + f" | {measure:.2f} |")
        # the report's shapes no general table was searched on, in the
        # ranking's order: each general table's count and its share of the
        # best of the shape's own tables
        held_out = [f for f in reported if f not in shapes and f in results["shapes"]]
        own = {f: max(own_counts(results["shapes"][f]), default=0.0) for f in held_out}
        lines += ["", "| general table, on shapes no general search saw | " + " | ".join(f"{f} (its own table {own[f]:,.1f})" for f in held_out) + " |",
                  "|---|" + "---:|" * len(held_out)]
        for run, _, _ in ranked:
            cells = []
            for f in held_out:
                c = count_of(results, "shapes", f, run)
                if c is None:
                    cells.append("-")
                elif own[f]:
                    cells.append(f"{c['per_million']:,.1f} ({c['per_million'] / own[f]:.2f})")
                else:
                    cells.append(f"{c['per_million']:,.1f}")
            lines.append(f"| {run} | " + " | ".join(cells) + " |")
        # the same tables at twice the noise, where evaluated: ranked by
        # the measure at both levels, and each held-out shape's 2x / default
        ranked_2x = {run: measure for run, _, measure in general_ranking(results, shapes, "shapes_2x")}
        if ranked_2x:
            both = sorted(((run, measure, ranked_2x[run]) for run, _, measure in ranked if run in ranked_2x),
                          key=lambda r: -(r[1] + r[2]))
            lines += ["", "| general table | sum at the default noise | sum at twice it | both | "
                      + " | ".join(f"{f}: 2x / default" for f in held_out) + " |",
                      "|---|" + "---:|" * (3 + len(held_out))]
            for run, default, twice in both:
                cells = []
                for f in held_out:
                    c1 = count_of(results, "shapes", f, run)
                    c2 = count_of(results, "shapes_2x", f, run)
                    cells.append(f"{c2['per_million'] / c1['per_million']:.2f}" if c1 and c2 and c1["per_million"] else "-")
                lines.append(f"| {run} | {default:.2f} | {twice:.2f} | {default + twice:.2f} | " + " | ".join(cells) + " |")
            lines += ["", f"Ranked by the sum at both noise levels, the first is `{both[0][0]}`; by the default noise alone, `{ranked[0][0]}`."]
    lines += ["", "| search | field | senses | noise | hasher | start | generations | steps | validation: start | validation: result | result / start |",
              "|---|---|---|---|---|---|---:|---:|---:|---:|---:|"]
    for s in results["searches"]:
        ratio = f"{s['result_validation'] / s['start_validation']:.2f}" if s["start_validation"] else "-"
        lines.append(
            f"| {s['name']} | {s['field']} | {s['sensors']} | {s['noise']} | {s['hasher']} | {s['start']} | {s['generations']} | {s['steps']:,} "
            f"| {s['start_validation']} | {s['result_validation']} | {ratio} |")
    return "\n".join(lines)


def render(results_path, doc_path, check):
    results = json.load(open(results_path))
    doc = open(doc_path).read()
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    new = head + BEGIN + "\n" + tables(results) + "\n" + END + tail
    if check:
        if new != doc:
            sys.exit(f"{doc_path}: its tables are not what {results_path} gives; run scripts/policy-search publish")
        return
    with open(doc_path + ".tmp", "w") as fh:
        fh.write(new)
    os.replace(doc_path + ".tmp", doc_path)


if __name__ == "__main__":
    if sys.argv[1] == "--check":
        render(sys.argv[2], sys.argv[3], True)
    else:
        publish(sys.argv[1], sys.argv[2])
        render(sys.argv[2], sys.argv[3], False)
