"""The Python pages show the examples that run and the figures that were
measured: docs/python-examples.md the example files verbatim,
docs/python-results.md the learning tables rendered from their results
files, docs/python-performance.md the throughput table and docs/python.md
the comparison with VMAS rendered from the results file of the benchmark
(python/benchmarks/throughput.py), which also runs here at a tiny scale,
and docs/python-performance.md the cache lines a step fetches
(python/benchmarks/cache_lines.py)."""

import argparse
import importlib.util
import json
import statistics
import subprocess
import sys

import pytest


def benchmark(repo, name):
    """The module of python/benchmarks/NAME.py (not a package: loaded from its file)."""
    here = str(repo / "python" / "benchmarks")
    if here not in sys.path:
        sys.path.insert(0, here)  # the benchmarks import their sibling results_file
    spec = importlib.util.spec_from_file_location(name, repo / "python" / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_examples_in_the_docs_are_the_example_files(repo):
    doc = (repo / "docs" / "python-examples.md").read_text()
    for name in ["tabular_q.py", "ppo_sb3.py"]:
        code = (repo / "python" / "examples" / name).read_text()
        assert f"```python\n{code}```" in doc, f"docs/python-examples.md does not show python/examples/{name} as it is"


def test_the_throughput_table_is_rendered_from_the_measured_results(repo):
    throughput = benchmark(repo, "throughput")
    table = throughput.render(json.loads((repo / "docs" / "python-throughput.json").read_text()))
    assert table in (repo / "docs" / "python-performance.md").read_text(), "docs/python-performance.md does not hold the rendered table"


def test_the_cache_line_table_is_rendered_from_the_counts_and_what_the_docs_say_of_it_holds(repo):
    cache_lines = benchmark(repo, "cache_lines")
    results = json.loads((repo / "docs" / "python-cache-lines.json").read_text())
    assert cache_lines.render(results) in (repo / "docs" / "python-performance.md").read_text(), \
        "docs/python-performance.md does not hold the rendered cache-line table"
    rows = {row["worlds"]: row for row in results["rows"]}
    instructions = [row["instructions"] for worlds, row in rows.items() if worlds >= 64]
    assert max(instructions) < 1.1 * min(instructions), "the instructions stay within a tenth of each other"
    for worlds, row in rows.items():
        if worlds >= 64:
            assert 200 <= row["first_level_misses"] <= 250, f"about 225 first-level misses at {worlds} worlds"
        else:
            assert row["second_level_misses"] < 0.1 * row["first_level_misses"], \
                f"the lines stay in the second level at {worlds} worlds"
        if worlds >= 128:
            assert row["second_level_misses"] >= 0.8 * row["first_level_misses"], \
                f"nearly all also miss the second level at {worlds} worlds"
            assert 11_000 <= row["second_level_misses"] * 64 <= 13_000, f"about 12 KB a step at {worlds} worlds"


def test_the_cache_line_benchmark_counts_every_world_count_at_a_tiny_scale(repo, tmp_path):
    out = tmp_path / "cache-lines.json"
    done = subprocess.run([sys.executable, str(repo / "python" / "benchmarks" / "cache_lines.py"), "--tiny",
                           "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    results = json.loads(out.read_text())
    assert [row["worlds"] for row in results["rows"]] == [2, 4]
    for row in results["rows"]:
        assert row["instructions"] > 1000, f"a world step is thousands of instructions: {row}"
        assert row["first_level_misses"] > 0, row
    assert done.stdout == benchmark(repo, "cache_lines").render(results)


def test_the_comparison_with_vmas_is_rendered_from_the_measured_results_of_the_pinned_version(repo):
    throughput = benchmark(repo, "throughput")
    results = json.loads((repo / "docs" / "python-throughput.json").read_text())
    assert results["versions"]["vmas"] == throughput.VMAS_VERSION
    sides = {(row["side"], row.get("threads")) for row in results["rows"]}
    assert {("ours", 1), ("vmas", 1)} <= sides and len({t for _, t in sides if t}) == 2, "both sides at one thread and on every core"
    table = throughput.render_vmas(results)
    assert table in (repo / "docs" / "python.md").read_text(), "docs/python.md does not hold the rendered comparison"
    # what docs/python.md says the targets would take
    per_cpu = {row["name"]: statistics.median(row["cpu_runs"]) for row in results["rows"]}
    native = per_cpu["host run, random actions (one thread)"]
    transport = {row["worlds"]: statistics.median(row["cpu_runs"]) for row in results["rows"]
                 if row["side"] == "vmas" and row["threads"] == 1 and "transport" in row["name"]}
    ours_64 = per_cpu["vector_env, 64 worlds, 1 thread, random actions"]
    assert 3 * transport[512] > native, "3x VMAS at 512 worlds is beyond one native world in the cache"
    assert 1.1 < 10 * transport[64] / ours_64 < 1.2, "10x at 64 worlds is about a seventh more than ours"
    install = f"pip install vmas=={throughput.VMAS_VERSION}"
    assert install in (repo / "docs" / "python-performance.md").read_text() and install in throughput.__doc__


def test_the_throughput_benchmark_runs_every_configuration_at_a_tiny_scale(repo, host):
    throughput = benchmark(repo, "throughput")
    args = argparse.Namespace(host=str(host), vmas_python=None, rounds=1, tiny=True)
    results = throughput.measure(args)
    rows = results["rows"]
    assert all(len(row["runs"]) == 1 and row["runs"][0] > 0 and row["cpu_runs"][0] > 0 for row in rows)
    assert results["bytes_per_world"] > 0, "more worlds hold more memory"
    pucks, few = results["bytes_per_world_few_pucks"]
    assert 0 < few < results["bytes_per_world"], f"a world of {pucks} pucks holds less than one of 250"
    scale = throughput.Scale(tiny=True)
    for worlds in scale.worlds:
        for threads in {1, max(row.get("threads", 1) for row in rows)}:
            assert throughput.find(rows, "ours", worlds, threads) is not None, (worlds, threads)
    table = throughput.render(results)
    assert all(row["name"] in table for row in rows)
    assert table.count("- Target") == 1 + 2 * len({1, max(row.get("threads", 1) for row in rows)})


def test_the_learning_table_is_rendered_from_the_measured_results(repo):
    learning = benchmark(repo, "learning")
    table = learning.render(json.loads((repo / "docs" / "python-learning.json").read_text()))
    assert table in (repo / "docs" / "python-results.md").read_text(), "docs/python-results.md does not hold the rendered learning table"


def test_what_the_docs_say_of_the_learning_figures_holds_in_the_measured_results(repo):
    rows = json.loads((repo / "docs" / "python-learning.json").read_text())["rows"]
    by = {(r["learner"].split(" (")[0], r["reward"]): r for r in rows}
    still, random = by[("robots standing still", None)], by[("random actions", None)]
    baselines = max(still["final_eval"], random["final_eval"])
    tabular = by[("tabular Q", "reference")]
    assert tabular["trained_formations"] > 0 and tabular["exported_formations"] > 0 and tabular["formations"] > 0
    assert tabular["final_eval"] > baselines
    assert by[("tabular Q", "thesis")]["formations"] == by[("tabular Q", "success-shaped")]["formations"] == 0
    for ppo in (by[("shared-policy PPO", "reference")], by[("SB3 PPO", "reference")]):
        assert ppo["formations"] > 0 and ppo["exported_formations"] > 0 and ppo["trained_formations"] == 0
        assert ppo["final_eval"] > baselines
    assert by[("shared-policy PPO", "per-robot")]["formations"] == by[("shared-policy PPO", "success-shaped")]["formations"] == 0
    network = by[("shared Q-network", "reference")]
    assert network["trained_formations"] > 0 and network["formations"] == 0
    assert random["final_eval"] < still["final_eval"]


def test_the_million_step_learning_table_is_rendered_and_what_the_docs_say_of_it_holds(repo):
    learning = benchmark(repo, "learning")
    results = json.loads((repo / "docs" / "python-learning-1m.json").read_text())
    assert learning.render(results) in (repo / "docs" / "python-results.md").read_text()
    assert results["budget_steps"] <= 1_000_000 and len(results["eval_seeds"]) == 10
    by = {(r["learner"].split(" (")[0], r["reward"]): r for r in results["rows"]}
    still, random = by[("robots standing still", None)], by[("random actions", None)]
    tabular = by[("tabular Q", "reference")]
    assert tabular["exported_formations"] >= 0.9 * tabular["trained_formations"] > 0
    for ppo in (by[("shared-policy PPO", "reference")], by[("SB3 PPO", "reference")]):
        assert ppo["formations"] >= tabular["formations"] / 4 > 0
        assert ppo["final_eval"] > max(still["final_eval"], random["final_eval"])
        assert ppo["exported_formations"] > ppo["trained_formations"] > 0
    for reward in ("per-robot", "success-shaped"):
        assert by[("shared-policy PPO", reward)]["formations"] == by[("shared-policy PPO", reward)]["trained_formations"] == 0


def test_the_multi_agent_learning_table_is_rendered_and_what_the_docs_say_of_it_holds(repo):
    learning = benchmark(repo, "learning")
    results = json.loads((repo / "docs" / "python-learning-q.json").read_text())
    assert learning.render(results) in (repo / "docs" / "python-results.md").read_text()
    by = {(r["learner"].split(" (")[0], r["reward"]): r for r in results["rows"]}
    still, random = by[("robots standing still", None)], by[("random actions", None)]
    tabular, shared = by[("tabular Q", "reference")], by[("shared Q-network", "reference")]
    assert tabular["trained_formations"] > shared["trained_formations"] >= tabular["trained_formations"] / 4 > 0
    assert shared["formations"] >= tabular["formations"] / 4 > 0
    assert shared["final_eval"] > max(still["final_eval"], random["final_eval"])
    assert shared["exported_formations"] >= 0.9 * shared["trained_formations"]


def test_the_exploration_table_is_rendered_and_what_the_docs_say_of_it_holds(repo):
    learning = benchmark(repo, "learning")
    results = json.loads((repo / "docs" / "python-learning-exploration.json").read_text())
    assert learning.render(results) in (repo / "docs" / "python-results.md").read_text()
    rows = {r["learner"]: r for r in results["rows"]}
    greedy = rows["tabular Q (tabular_q.py)"]
    variant = lambda initial_q, epsilon: rows[f"tabular Q (tabular_q.py), initial Q {initial_q}, epsilon {epsilon}"]
    assert variant(0, 0)["formations"] >= greedy["formations"] / 2 > 0
    pessimistic = variant(-10, 0)
    assert pessimistic["formations"] == pessimistic["trained_formations"] == pessimistic["exported_formations"] == 0
    for epsilon in (0.1, 0.01):
        explored = variant(1, epsilon)
        assert explored["formations"] == explored["exported_formations"] == 0, epsilon


def test_a_bad_exploration_setting_of_the_learning_benchmark_is_named(repo):
    learning = benchmark(repo, "learning")
    assert learning.exploration("-10,0.1") == (-10.0, 0.1)
    for text, words in [("1", "INITIAL_Q,EPSILON"), ("a,b", "INITIAL_Q,EPSILON"), ("1,1.5", "epsilon 1.5")]:
        with pytest.raises(argparse.ArgumentTypeError, match=words):
            learning.exploration(text)


def test_the_install_section_says_what_installing_builds_how_long_and_how_to_get_a_cpu_only_torch(repo):
    doc = (repo / "docs" / "python.md").read_text()
    install = doc[doc.index("## Install\n"):doc.index("## Settings\n")]
    assert "pip install -v ./python" in install, "-v: cargo's progress, not only 'still running'"
    for words in ("What `pip install ./python` builds", "in release", "Measured", "2 cores",
                  "pip install torch --index-url https://download.pytorch.org/whl/cpu"):
        assert words in install, words
