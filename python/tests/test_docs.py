"""docs/python.md shows the examples that run and the figures that were
measured: the example files verbatim, and the throughput table rendered
from the results file of the benchmark (python/benchmarks/throughput.py)."""

import importlib.util
import json


def test_the_examples_in_the_docs_are_the_example_files(repo):
    doc = (repo / "docs" / "python.md").read_text()
    for name in ["tabular_q.py", "ppo_sb3.py"]:
        code = (repo / "python" / "examples" / name).read_text()
        assert f"```python\n{code}```" in doc, f"docs/python.md does not show python/examples/{name} as it is"


def test_the_throughput_tables_are_rendered_from_the_measured_results(repo):
    spec = importlib.util.spec_from_file_location("throughput", repo / "python" / "benchmarks" / "throughput.py")
    throughput = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(throughput)
    table = throughput.render(json.loads((repo / "docs" / "python-throughput.json").read_text()))
    for doc in ["python.md", "performance.md"]:
        assert table in (repo / "docs" / doc).read_text(), f"docs/{doc} does not hold the rendered table"


def test_the_learning_table_is_rendered_from_the_measured_results(repo):
    spec = importlib.util.spec_from_file_location("learning", repo / "python" / "benchmarks" / "learning.py")
    learning = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(learning)
    table = learning.render(json.loads((repo / "docs" / "python-learning.json").read_text()))
    assert table in (repo / "docs" / "python.md").read_text(), "docs/python.md does not hold the rendered learning table"
