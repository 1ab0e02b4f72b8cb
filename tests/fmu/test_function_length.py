"""No function of the package is over :data:`MAX_FUNCTION_LINES` lines (the project's standard): a longer
one does several jobs, which get names of their own. Read from the source with ``ast`` (a function's
lines from its ``def``, decorators excluded, to its last line; nested functions count in the function
that holds them and on their own)."""
import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "fmu_src" / "restitution"
MAX_FUNCTION_LINES = 150


def long_functions(source: str, limit: int = MAX_FUNCTION_LINES) -> list[tuple[str, int]]:
    """(name, lines) of every function of ``source`` over ``limit`` lines."""
    return [(node.name, node.end_lineno - node.lineno + 1) for node in ast.walk(ast.parse(source))
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.end_lineno - node.lineno + 1 > limit]


def test_no_function_of_the_package_is_over_150_lines():
    found = {path.relative_to(PACKAGE).as_posix(): long for path in sorted(PACKAGE.rglob("*.py"))
             if "__pycache__" not in path.parts and (long := long_functions(path.read_text(encoding="utf-8")))}
    assert found == {}


def test_a_long_function_is_found():
    body = "".join(f"        x{i} = {i}\n" for i in range(MAX_FUNCTION_LINES))  # def line + 150 = 151 lines
    source = f"def short():\n    return 1\n\n\nclass A:\n    def long(self):\n{body}"
    assert long_functions(source) == [("long", MAX_FUNCTION_LINES + 1)]
    assert long_functions(source.replace("        x0 = 0\n", "")) == []
