"""The structure of the pure-Python package (python/roughscope): one HTML helper module, one
demo module, rendering modules without physics of their own, no import cycles, no module reaching
into another's private names — checked on the sources with `ast` — and the helpers' output
against known strings, the physics the demo and the figures take from `_core` against
independent values."""

import ast
import math
import pathlib

import numpy as np
import pytest

from roughscope import _core, _html, demo

PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "python" / "roughscope"
MODULES = {p.stem: ast.parse(p.read_text(encoding="utf-8"), filename=str(p))
           for p in sorted(PACKAGE.glob("*.py"))}
# Modules of the package that are not Python files (the compiled module).
COMPILED = {"_core"}


def package_modules():
    return set(MODULES) | COMPILED


def imports_of(name, tree):
    """[(module imported, names taken from it, line)] of the package's own modules that `tree`
    imports, wherever (module level or inside a function)."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level == 1 and node.module is None:  # from . import a, b
                for alias in node.names:
                    found.append((alias.name, [], node.lineno))
            elif (node.level == 1 and node.module) or (node.level == 0 and node.module and
                                                        node.module.startswith("roughscope.")):
                module = node.module.split(".")[-1]
                found.append((module, [a.name for a in node.names], node.lineno))
            elif node.level == 0 and node.module == "roughscope":  # from roughscope import a
                for alias in node.names:
                    if alias.name in package_modules():
                        found.append((alias.name, [], node.lineno))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("roughscope."):
                    found.append((alias.name.split(".")[1], [], node.lineno))
    return found


def import_graph(modules):
    """module → set of package modules it imports (the package's __init__ left out: every
    submodule is imported below it, and its lazy __getattr__ names them all)."""
    graph = {}
    for name, tree in modules.items():
        if name == "__init__":
            continue
        graph[name] = {m for m, _, _ in imports_of(name, tree)
                       if m in modules and m not in ("__init__", name)}
    return graph


def find_cycle(graph):
    """One import cycle as a list of modules (first == last), or None."""
    state = {}

    def visit(node, path):
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return path[path.index(nxt):] + [nxt]
            if nxt not in state:
                cycle = visit(nxt, path + [nxt])
                if cycle:
                    return cycle
        state[node] = "done"
        return None

    for start in sorted(graph):
        if start not in state:
            cycle = visit(start, [start])
            if cycle:
                return cycle
    return None


def private_uses(modules):
    """(module, what, line) for every use of another package module's private name: an import
    `from .x import _y` of a name that is not itself a module, or an attribute `x._y` of a
    module bound by `from . import x`."""
    found = []
    for name, tree in modules.items():
        bound = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level == 1 and node.module is None:
                for alias in node.names:
                    bound[alias.asname or alias.name] = alias.name
        for module, names, line in imports_of(name, tree):
            for n in names:
                if n.startswith("_") and not n.startswith("__") and n not in package_modules():
                    found.append((name, f"from .{module} import {n}", line))
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in bound and node.attr.startswith("_")
                    and not node.attr.startswith("__")):
                found.append((name, f"{node.value.id}.{node.attr}", node.lineno))
    return found


def top_level_functions(tree):
    return {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}


# ---- the checks are able to fail -----------------------------------------------------------

def test_the_cycle_finder_finds_a_cycle_and_a_private_import():
    fake = {"a": ast.parse("from . import b\n"),
            "b": ast.parse("def f():\n    from .c import _helper\n"),
            "c": ast.parse("from .a import thing\nfrom . import b\nb._secret()\n")}
    cycle = find_cycle(import_graph(fake))
    assert cycle is not None and cycle[0] == cycle[-1] and set(cycle) == {"a", "b", "c"}
    uses = private_uses(fake)
    assert ("b", "from .c import _helper", 2) in uses
    assert ("c", "b._secret", 3) in uses
    assert find_cycle(import_graph({"a": ast.parse("from . import b"),
                                    "b": ast.parse("import numpy")})) is None


# ---- the package ---------------------------------------------------------------------------

def test_the_package_has_no_import_cycle():
    assert "report" in MODULES and "_html" in MODULES and "demo" in MODULES
    cycle = find_cycle(import_graph(MODULES))
    assert cycle is None, " → ".join(cycle)


def test_no_module_imports_another_modules_private_name():
    assert private_uses(MODULES) == []


def test_no_module_but_the_package_imports_by_name_at_run_time():
    # importlib.import_module would hide an edge from the import graph above.
    for name, tree in MODULES.items():
        if name == "__init__":
            continue
        calls = [n for n in ast.walk(tree) if isinstance(n, ast.Attribute)
                 and n.attr in ("import_module", "__import__")]
        assert not calls, f"{name}.py imports a module by name"


# The helpers the report pages share: each defined in one module (and the old copies nowhere).
SHARED_HELPERS = {"escape": "_html", "fmt": "_html", "number": "_html", "quantity": "_html",
                  "embedded_image": "_html", "linked_figure": "_html", "verdict": "_html",
                  "within_two_sigma": "_html", "page_html": "_html", "write_page": "_html",
                  "prepare_folder": "_html", "one_line_error": "_html", "pyplot": "_plotting",
                  "save": "_plotting"}
OLD_COPIES = ("_e", "_fmt", "_num", "_rel", "_img_tag", "_pass", "_pyplot", "_camera",
              "_exposure", "_peak")


def test_each_shared_helper_is_defined_once_in_its_module():
    defined = {name: top_level_functions(tree) for name, tree in MODULES.items()}
    for helper, home in SHARED_HELPERS.items():
        where = sorted(m for m, functions in defined.items() if helper in functions)
        assert where == [home], (helper, where)
    for old in OLD_COPIES:
        where = sorted(m for m, functions in defined.items() if old in functions)
        assert where == [], (old, where)


def test_only_the_html_module_escapes_and_encodes_images():
    for name, tree in MODULES.items():
        stdlib = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        stdlib |= {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)
                   and n.level == 0}
        if name != "_html":
            assert not stdlib & {"html", "base64"}, name


def test_only_the_demo_module_renders_synthetic_photographs():
    writers = {"write_capture", "render_capture"}
    for name, tree in MODULES.items():
        used = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)} & writers
        if name != "demo":
            assert not used, (name, used)
    assert {"write_capture", "render_capture"} <= {
        n.attr for n in ast.walk(MODULES["demo"]) if isinstance(n, ast.Attribute)}


def test_report_sections_use_the_html_helpers():
    for name in ("report", "report_measure", "report_objects", "report_curet",
                 "report_estimation", "report_simulation", "report_surface"):
        assert "_html" in {m for m, _, _ in imports_of(name, MODULES[name])}, name


# ---- the helpers ---------------------------------------------------------------------------

def test_escape():
    assert _html.escape("<script>alert('x')</script>") == \
        "&lt;script&gt;alert(&#x27;x&#x27;)&lt;/script&gt;"
    assert _html.escape('a & "b"') == "a &amp; &quot;b&quot;"
    assert _html.escape(0.5) == "0.5"
    assert _html.escape(ValueError("x < 1")) == "x &lt; 1"


def test_value_with_error():
    assert _html.fmt(0.2999, 0.00025) == "0.2999 ± 0.00025"
    assert _html.fmt(1.23456789, 0.0123) == "1.235 ± 0.012"
    assert _html.fmt(1.23456789, 0.0123, digits=3) == "1.23 ± 0.012"
    assert _html.fmt(0.98765, 0.01234, decimals=3) == "0.988 ± 0.012"
    assert _html.fmt(2.5) == "2.5"
    assert _html.fmt(2.5, 0.0) == "2.5"  # a zero error is not shown
    assert _html.fmt(2.5, None) == "2.5"
    assert _html.fmt(None, 0.1) == "–"
    assert _html.fmt(12345678.0) == "1.235e+07"


def test_numbers_quantities_and_marks():
    assert _html.number(None) == "–" and _html.number(None, missing="—") == "—"
    assert _html.number(1.0 / 3.0, ".4f") == "0.3333"
    assert _html.quantity(0.5, "µm") == "0.5 µm" and _html.quantity("<gaussian>") == \
        "&lt;gaussian&gt;" and _html.quantity(None) == "–"
    assert _html.relative_difference(1.01, 1.0) == "+1.000 %"
    assert _html.relative_difference(1.0, 0) == "—" and _html.relative_difference(None, 1) == "—"
    assert "pass" in _html.verdict(True) and ">yes<" in _html.verdict(True)
    assert "fail" in _html.verdict(False) and ">no<" in _html.verdict(False)
    assert ">yes<" in _html.within_two_sigma(1.0, 0.1, 1.19)
    assert ">no<" in _html.within_two_sigma(1.0, 0.1, 1.21)
    assert _html.within_two_sigma(1.0, None, 1.0) == "" == _html.within_two_sigma(1.0, 0.1, None)


def test_images_and_pages():
    tag = _html.embedded_image(b"\x89PNG", 'a "b"')
    assert tag == '<img src="data:image/png;base64,iVBORw==" alt="a &quot;b&quot;">'
    fig = _html.linked_figure("x<.png", "alt", "<b>caption</b>")
    assert "src='x&lt;.png'" in fig and "<figcaption><b>caption</b></figcaption>" in fig
    page = _html.page_html("<p>body</p>", "a <title>", "meta &amp; more")
    assert page.startswith("<!DOCTYPE html>") and "<title>a &lt;title&gt;</title>" in page
    assert "<style>" + _html.CSS + "</style>" in page and "<p>body</p>" in page
    assert '<p class="meta">meta &amp; more</p>' in page


def test_write_page_replaces_index_only(tmp_path):
    (tmp_path / "other.txt").write_text("mine")
    index = _html.write_page(tmp_path, "<html>1</html>")
    assert index == tmp_path / "index.html" and index.read_text() == "<html>1</html>"
    _html.write_page(tmp_path, "<html>2</html>")
    assert index.read_text() == "<html>2</html>"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["index.html", "other.txt"]
    with pytest.raises(NotADirectoryError, match="not a folder"):
        _html.write_page(tmp_path / "other.txt", "x")


def test_one_line_error():
    exc = FileNotFoundError(2, "No such file or directory", "/nowhere/x")
    assert _html.one_line_error(exc) == "/nowhere/x: no such file or directory"
    assert _html.one_line_error(ValueError("two\n  lines")) == "two lines"
    assert _html.one_line_error(ValueError()) == "ValueError"


# ---- the physics comes from _core ------------------------------------------------------------

def test_specular_photograph_brightness_inverts_to_the_samples_sigma():
    sample = next(s for s in demo.SAMPLES if "specular_theta_deg" in s)
    e_dif, e_tot = demo.specular_brightness(sample)
    r_spec = _core.specular_reflectance_from_brightness(e_tot, e_dif)
    theta = sample["specular_theta_deg"]
    # Eq. 13 inverted independently (the estimator of §4.1.1) gives back the truth...
    sigma = _core.sigma_from_specular(r_spec, theta, demo.WAVELENGTH_UM)
    assert sigma == pytest.approx(sample["sigma_um"], rel=1e-12)
    # ... and R_spec = exp(−g) with g = (4πσ cos θ/λ)² written out.
    g = (4 * math.pi * sample["sigma_um"] * math.cos(math.radians(theta)) / demo.WAVELENGTH_UM) ** 2
    assert r_spec == pytest.approx(math.exp(-g), rel=1e-12)


def test_srgb_encode_is_the_iec_curve():
    u = np.array([0.0, 0.001, 0.0031308, 0.01, 0.18, 0.5, 1.0])
    iec = np.where(u <= 0.0031308, 12.92 * u, 1.055 * u ** (1 / 2.4) - 0.055)
    np.testing.assert_allclose(_core.srgb_encode(u), iec, rtol=1e-14, atol=1e-15)
    assert _core.srgb_encode(0.5) == pytest.approx(0.7353569830524495, rel=1e-14)
    assert isinstance(_core.srgb_encode(1.0), float) and _core.srgb_encode(1.0) == \
        pytest.approx(1.0, rel=1e-14)
    with pytest.raises(ValueError, match=r"linear = 1\.5 is outside the valid range \[0, 1\]"):
        _core.srgb_encode([0.5, 1.5])
    with pytest.raises(TypeError):
        _core.srgb_encode("0.5")


def test_acf_model_is_the_papers_correlation_functions():
    tau = np.array([-3.0, 0.0, 0.5, 2.0, 8.0])
    T = 2.0
    np.testing.assert_allclose(_core.acf_model(tau, T, "gaussian"), np.exp(-(tau / T) ** 2),
                               rtol=1e-14)
    np.testing.assert_allclose(_core.acf_model(tau, T, correlation="exponential"),
                               np.exp(-np.abs(tau) / T), rtol=1e-14)
    # T is the 1/e length of both.
    assert _core.acf_model(T, T) == pytest.approx(math.exp(-1), rel=1e-15)
    assert _core.acf_model(T, T, "exponential") == pytest.approx(math.exp(-1), rel=1e-15)
    with pytest.raises(ValueError, match="T_um"):
        _core.acf_model(1.0, 0.0)
    with pytest.raises(ValueError, match="correlation"):
        _core.acf_model(1.0, 1.0, "lorentzian")
    with pytest.raises(ValueError, match="lag_um and T_um cannot be broadcast together"):
        _core.acf_model(np.zeros(2), np.ones(3))
    assert _core.acf_model(np.zeros((2, 1)), np.ones(3)).shape == (2, 3)


def test_the_acf_model_fits_what_surface_statistics_fitted():
    # The fitted T of a generated Gaussian surface draws, through acf_model, a curve close to the
    # measured ACF at short lags (the figure's overlay is the model the library fitted).
    heights = _core.generate_surface(correlation="gaussian", sigma_um=0.5, T_um=8.0, nx=256,
                                     ny=256, dx_um=1.0, seed=1)
    doc = _core.surface_statistics(heights, 1.0, curves=True, level="plane")
    curve = doc["curves"]["acf_x"]
    lag = np.array([np.nan if v is None else v for v in curve["lag_um"]], float)
    acf = np.array([np.nan if v is None else v for v in curve["acf"]], float)
    near = lag <= doc["T_fit_gaussian_um"]
    model = _core.acf_model(lag[near], doc["T_fit_gaussian_um"], "gaussian")
    assert np.max(np.abs(model - acf[near])) < 0.05


def test_rms_slope_of_the_surface_section_truth():
    assert _core.rms_slope(0.5 / 8.0) == pytest.approx(math.sqrt(2) * 0.5 / 8.0, rel=1e-15)
