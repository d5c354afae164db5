"""The layout: imports run down the pipeline, with no cycle between fem_twin's modules."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "fem_twin"


def _module(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set:
    """fem_twin modules imported anywhere in ``path`` (also inside functions)."""
    name = _module(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:            # "from . import tables" names a module
                sub = f"{target}.{alias.name}"
                out.add(sub if (PACKAGE.parent / (sub.replace(".", "/") + ".py")).exists()
                        else target)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return {m for m in out if m == "fem_twin" or m.startswith("fem_twin.")} - {name}


def test_no_import_cycle_between_modules():
    graph = {_module(p): _imports(p) for p in PACKAGE.rglob("*.py")}
    graph = {m: {d for d in deps if d in graph and d != "fem_twin"} for m, deps in graph.items()}
    state = {}

    def visit(m, path):
        state[m] = "open"
        for d in graph[m]:
            if state.get(d) == "open":
                raise AssertionError("import cycle: " + " -> ".join(path + [m, d]))
            if d not in state:
                visit(d, path + [m])
        state[m] = "done"

    for m in sorted(graph):
        if m not in state:
            visit(m, [])


def test_every_raise_is_a_fem_twin_error():
    """Every exception fem_twin raises on purpose derives from
    FemTwinError (and from the builtin a caller expects), so ``except FemTwinError`` catches
    all of them.  Walks every ``raise Name(...)`` of the package and resolves the name in
    its module; re-raises (``raise``, ``raise err``) are not new errors."""
    import importlib

    from fem_twin.errors import FemTwinError
    bare = []
    for path in PACKAGE.rglob("*.py"):
        module = importlib.import_module(_module(path))
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call):
                func = node.exc.func
                name = func.id if isinstance(func, ast.Name) else ast.unparse(func)
                cls = getattr(module, name, None) if isinstance(func, ast.Name) else None
                if not (isinstance(cls, type) and issubclass(cls, FemTwinError)):
                    bare.append(f"{path.relative_to(PACKAGE)}:{node.lineno} raise {name}")
    assert not bare, "\n".join(bare)


def test_run_files_are_named_only_by_the_run_layout():
    """The names of the files a run writes and reads appear once, in
    fem_twin/io/layout.py (RunLayout); every other module asks it for the path.
    (samples.py names the bundled sample's input maps, which happen to share a pattern.)"""
    import re
    names = set(re.findall(r'"([\w{}*]+\.(?:npz|json|csv|nc|png|log|vtu|html))"',
                           (PACKAGE / "io" / "layout.py").read_text()))
    assert {"summary.json", "stribeck.csv", "flow_factors.npz", "results.nc"} <= names
    elsewhere = [f"{path.relative_to(PACKAGE)}: {name}" for path in PACKAGE.rglob("*.py")
                 if path.name not in ("layout.py", "samples.py") for name in names
                 if f'"{name}"' in path.read_text()]
    assert not elsewhere, elsewhere


def _layers() -> dict:
    """The layer of each package or module, from the table in fem_twin's docstring."""
    import re

    import fem_twin
    rows = re.findall(r"^ {4}(\d+(?:\.\d+)?) +([\w., ]+)$", fem_twin.__doc__, re.M)
    return {name.strip(): float(layer) for layer, names in rows for name in names.split(",")}


LAYERS = _layers()


def _layer(module: str) -> float:
    parts = module.split(".")[1:]
    for n in (2, 1):
        key = ".".join(parts[:n])
        if len(parts) >= n and key in LAYERS:
            return LAYERS[key]
    return 0


def test_imports_run_down_the_pipeline():
    """Topography -> contact -> micro -> macro -> stribeck -> the workflow
    (case, results, stages, pipeline, studies, report) -> the CLI: no stage imports a later
    one, and the workflow never imports from the CLI."""
    up = []
    for path in PACKAGE.rglob("*.py"):
        m = _module(path)
        if m == "fem_twin":
            continue
        up += [f"{m} -> {d}" for d in _imports(path)
               if d != "fem_twin" and _layer(d) > _layer(m)]
    assert not up, "imports against the pipeline's order:\n" + "\n".join(sorted(up))


def _rooms() -> dict:
    """The layer of each room of ``macro/`` and of each module of its porch, from the table
    in fem_twin.macro's docstring."""
    import re

    import fem_twin.macro
    rows = re.findall(r"^ {4}(\d+) +([\w, ]+)$", fem_twin.macro.__doc__, re.M)
    return {name.strip(): int(layer) for layer, names in rows for name in names.split(",")}


ROOMS = _rooms()
MACRO = PACKAGE / "macro"


def _room(module: str) -> str:
    """The room of a module of fem_twin.macro (its first part below macro/), or, for the
    porch, the module itself; the package ``fem_twin.macro`` is the porch's front."""
    parts = module.split(".")[2:]
    return parts[0] if parts else "__init__"


def test_the_macro_table_names_every_room_and_the_porch():
    """The table in fem_twin.macro's docstring names each room (a folder of macro/) and
    each module of the porch (macro/'s own modules) once, and the porch is on top."""
    rooms = {p.parent.name for p in MACRO.glob("*/__init__.py")}
    porch = {p.stem for p in MACRO.glob("*.py")} - {"__init__"}
    assert set(ROOMS) == rooms | porch, set(ROOMS) ^ (rooms | porch)
    assert min(ROOMS[m] for m in porch) > max(ROOMS[r] for r in rooms), ROOMS


def test_macro_rooms_import_down():
    """Inside macro/, no room imports a later room (laws -> film -> coupling -> reference,
    the table in fem_twin.macro's docstring) and none imports the porch, which sits on top
    (point, mixed, nested, estimate, figures and the package's own ``__init__``)."""
    top = max(ROOMS.values()) + 1
    rank = {**ROOMS, "__init__": top}
    up = []
    for path in MACRO.rglob("*.py"):
        m = _module(path)
        if m == "fem_twin.macro":
            continue
        up += [f"{m} -> {d}" for d in _imports(path) if d.startswith("fem_twin.macro")
               and rank[_room(d)] > rank[_room(m)]]
    assert not up, "imports against macro's rooms:\n" + "\n".join(sorted(up))


def test_architecture_md_names_every_package_and_no_missing_path():
    """ARCHITECTURE.md names every subpackage of fem_twin and every room of macro/ (as
    ``name/``, checked against the folders), and every path it gives into the package or
    the repository (``macro/film/reynolds.py``, ``stages/geometry.measured_ball``,
    ``benchmarks/run.py``) exists: a moved module leaves no stale line there."""
    import re
    root = PACKAGE.parent
    text = (root / "ARCHITECTURE.md").read_text()
    packages = sorted(str(p.parent.relative_to(PACKAGE)) for p in PACKAGE.rglob("__init__.py")
                      if p.parent != PACKAGE and "__pycache__" not in p.parts)
    unnamed = [p for p in packages if not re.search(rf"(?<![\w.-]){re.escape(p)}/", text)]
    assert not unnamed, f"packages ARCHITECTURE.md does not name: {unnamed}"
    tops = sorted({p.split("/")[0] for p in packages} | {"tests", "benchmarks", "docs",
                                                         "examples"})
    pattern = rf"(?<![\w/.-])((?:{'|'.join(tops)})(?:/\w+)*)(\.\w+)?"
    missing = sorted({path + ext for path, ext in re.findall(pattern, text) if not any(
        (base / path).is_dir() or (base / f"{path}.py").is_file()
        or (base / f"{path}{ext}").is_file() for base in (PACKAGE, root))})
    assert not missing, f"paths in ARCHITECTURE.md that do not exist: {missing}"
    import importlib
    names = re.findall(r"(?<![\w/.-])((?:[a-z_]+/)+[a-z_]+)\.([A-Za-z_][\w.]*[A-Za-z_])", text)
    gone = []
    for path, attr in sorted(set(names)):
        if (PACKAGE / f"{path}.py").is_file() and attr != "py":
            obj = importlib.import_module("fem_twin." + path.replace("/", "."))
            for name in attr.split("."):
                obj = getattr(obj, name, None)
            gone += [f"{path}.{attr}"] if obj is None else []
    assert not gone, f"names in ARCHITECTURE.md that their module does not hold: {gone}"


def test_result_variables_are_declared_once():
    """An output variable is declared in one place, so adding one touches
    at most two files: an operating point's grid fields are MixedResult's arrays, each with
    its unit in macro/coupling/result.FIELDS (checkpoints, VTU, fields.nc and the docs read it); a
    Stribeck curve's are StribeckCurve's arrays, each a column of stribeck/curve.COLUMNS with
    its CSV header and its results.nc unit (UNITS)."""
    from dataclasses import fields

    from fem_twin.macro.coupling.result import FIELDS, MixedResult
    from fem_twin.results import FIELD_UNITS
    from fem_twin.stribeck.curve import COLUMNS, HEADERS, UNITS, StribeckCurve
    arrays = {f.name for f in fields(MixedResult) if f.type == "np.ndarray"} - {"history"}
    assert arrays == set(FIELDS), arrays ^ set(FIELDS)
    assert len(FIELD_UNITS) == len(FIELDS)
    curve = {f.name for f in fields(StribeckCurve)
             if f.type == "np.ndarray" or f.name == "viscosity"}
    assert curve == set(COLUMNS) == set(HEADERS), curve ^ set(COLUMNS)
    assert set(COLUMNS) - {"speed", "viscosity"} <= set(UNITS)


def test_every_setting_another_section_sets_is_filled_from_it():
    """A stage setting declared ``setting(..., section=...)`` (E' and the
    hardness from [materials], C_f,b and the track radius from [tribometer], the cells'
    sliding kinematics) is filled from that section in one place, ``Case.filled``, which
    the stages' settings go through: a case's own values reach the cells and the macro
    solver."""
    from dataclasses import fields, replace

    from fem_twin.case.sections import FILLED, SECTIONS, Case, Geometry
    from fem_twin.macro import MacroSettings
    from fem_twin.macro.laws.thermal import ThermalSettings
    from fem_twin.micro.sliding import CellSettings
    from fem_twin.stages.factors import cell_settings
    from fem_twin.stages.requests import macro_settings
    classes = (CellSettings, MacroSettings, ThermalSettings, *SECTIONS.values())
    marked = {(cls.__name__, f.name): f.metadata["section"] for cls in classes
              for f in fields(cls) if f.metadata.get("section")}
    assert {name for _, name in marked} == set(FILLED)
    assert all(FILLED[name][0] == section for (_, name), section in marked.items())
    case = Case("filled", Geometry())
    case = replace(case, materials=replace(case.materials, e_pin=100e9, hardness=3e9),
                   tribometer=replace(case.tribometer, boundary_friction=0.12,
                                      sliding_radius=0.05))
    cell, macro = cell_settings(case), macro_settings(case)
    assert cell.e_reduced == macro.e_reduced == case.materials.e_reduced
    assert cell.e_reduced != CellSettings().e_reduced and cell.hardness == 3e9
    assert macro.boundary_friction == 0.12 and macro.track_radius == 0.05
    assert cell.slide_to_roll == 2.0                 # the cells slide; a ball's SRR comes later


#: literals equal to a table value that are not that value: (file, the table's name, why)
NOT_THE_TABLES = {("macro/reference/point_contact.py", "ROELANDS_ALPHA"):
                  "Moes' alpha of a test case",
                  ("io/samples.py", "PIN_DIAMETER"): "the sample map's 8 mm field of view"}


def test_the_papers_table_values_are_declared_once():
    """A distinctive value of the paper's tables (fem_twin/tables.py: its moduli, hardness,
    lubricant constants, pin and holder, C_f,b, the load) is written only there: anywhere
    else the same number is a second home, which a change of the table would miss.  Common
    numbers (0.3, 0.05, 50, 1e5) are left out: they are also other things."""
    import ast
    import math

    import fem_twin.tables as T
    distinctive = {k: v for k, v in vars(T).items() if k.isupper() and isinstance(v, float)
                   and k not in ("NU_STEEL", "RELAXATION_PCON", "LEVELLING_LOAD",
                                 "AMBIENT_PRESSURE")}
    twice = []
    for path in PACKAGE.rglob("*.py"):
        if path.name == "tables.py":
            continue
        where = str(path.relative_to(PACKAGE))
        for node in ast.walk(ast.parse(path.read_text())):
            sign = -1.0 if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub) else 1
            leaf = node.operand if sign < 0 else node
            if not (isinstance(leaf, ast.Constant) and type(leaf.value) in (int, float)):
                continue
            twice += [f"{where}:{node.lineno} {name}" for name, value in distinctive.items()
                      if math.isclose(sign * leaf.value, value, rel_tol=1e-9)
                      and (where, name) not in NOT_THE_TABLES]
    assert not twice, "the tables' values written again (use fem_twin.tables):\n" + "\n".join(
        twice)


#: the most required parameters, and parameters in all, of a public function of macro/
MOST_REQUIRED, MOST_PARAMETERS = 5, 12


def _public_functions(package: str):
    """``(qualified name, function)`` of every public function and public method of a
    public class defined in each module under ``package``."""
    import importlib
    import inspect
    import pkgutil
    root = importlib.import_module(package)
    for info in pkgutil.walk_packages(root.__path__, f"{package}."):
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                continue
            if inspect.isfunction(obj):
                yield f"{module.__name__}.{name}", obj
            elif inspect.isclass(obj):
                for attr, member in vars(obj).items():
                    method = inspect.isfunction(member) or isinstance(
                        member, (staticmethod, classmethod))
                    if method and not attr.startswith("_"):
                        yield f"{module.__name__}.{name}.{attr}", getattr(obj, attr)


def test_no_public_function_of_macro_takes_too_many_parameters():
    """No public function (nor public method) of a module under fem_twin/macro takes more
    than 5 required parameters or 12 in all (``self``, ``cls``, ``*args`` and ``**kwargs``
    aside): a longer list is a value waiting to be named (issue 86 item 2: the operating
    point carried down instead of its fields spread out)."""
    import inspect
    long = []
    for name, func in _public_functions("fem_twin.macro"):
        params = [p for p in inspect.signature(func).parameters.values()
                  if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
                  and p.name not in ("self", "cls")]
        required = [p for p in params if p.default is p.empty]
        if len(required) > MOST_REQUIRED or len(params) > MOST_PARAMETERS:
            long.append(f"{name}: {len(required)} required, {len(params)} in all")
    assert not long, "functions with too many parameters:\n" + "\n".join(long)
