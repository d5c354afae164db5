"""Sphinx extension: the reference pages generated from the code, so they cannot drift.

``reference/_generated/case_keys.md``: every case-file key from its one declaration
(:func:`fem_twin.checks.setting` fields of :data:`fem_twin.case.sections.SECTIONS`);
``reference/_generated/cli.md``: every command's ``--help`` from the CLI's parser.
"""

import re
from dataclasses import MISSING, fields
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "reference" / "_generated"


def _default(f) -> str:
    value = f.default if f.default is not MISSING else None
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:g}" if isinstance(v, float) else str(v)
                               for v in value) + "]"
    return "(none)" if value is None else f"{value:g}" if isinstance(value, float) else str(value)


def case_keys() -> str:
    """One section per case-file table: its doc and a row per key."""
    from fem_twin.case.sections import SECTIONS
    from fem_twin.checks import describe
    lines = []
    for name, cls in SECTIONS.items():
        doc = " ".join((cls.__doc__ or "").split("\n\n")[0].split())
        doc = doc.removeprefix(f"``[{name}]``: ")
        lines += [f"## `[{name}]`", "", doc, "",
                  "| key | default | unit, plausible range | meaning |", "|---|---|---|---|"]
        for f in fields(cls):
            if f.metadata.get("section"):              # a value another section sets
                continue
            d = describe(f)
            unit = d["unit"] or "-"
            if d["range"] is not None:
                unit += f"; {d['range'][0]:g} to {d['range'][1]:g}"
            if d["choices"]:
                unit = "one of " + ", ".join(f'`"{c}"`' for c in d["choices"])
            lines.append(f"| `{f.name}` | `{_default(f)}` | {unit} | {d['doc']} |")
        lines.append("")
    return "\n".join(lines)


def cli_reference() -> str:
    """``fem-twin --help`` and every subcommand's, nested."""
    import argparse
    import os

    from fem_twin.cli import build_parser
    os.environ["COLUMNS"] = "100"                 # the same text on every terminal
    def walk(parser, prog, depth):
        out = [f"{'#' * depth} `{prog}`", "", "```text", parser.format_help().rstrip(), "```",
               ""]
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    out += walk(sub, f"{prog} {name}", min(depth + 1, 4))
        return out

    return "\n".join(walk(build_parser(), "fem-twin", 2))


def outputs() -> str:
    """The columns of ``stribeck.csv`` and the variables of ``results.nc`` and ``fields.nc``
    with their units, from the writers' own tables."""
    from fem_twin.macro.estimate import PARTS
    from fem_twin.results import FIELD_UNITS
    from fem_twin.stribeck.curve import BOUNDARY_SHARE, HEADERS, LEGACY, OPTIONAL, UNITS
    lines = ["## `stribeck.csv`", "", "One row per point, curves one after another.", "",
             "| column | meaning |", "|---|---|"]
    for key, header in HEADERS.items():
        meaning = {"speed": "sliding speed U (a ball: entrainment speed u_m)",
                   "viscosity": "mu_0 of the curve"}.get(key, UNITS.get(key, ("", ""))[1])
        lines.append(f"| `{header}` | {meaning} |")
    lines += ["| `cf_err` | estimated discretisation error of C_f (both scales, "
              "{doc}`/accuracy`) |",
              "| `cf_min`, `cf_max` | the patch scatter band (`[run] patch_band`) |",
              f"| `{BOUNDARY_SHARE[0]}` | {BOUNDARY_SHARE[2]} |",
              "| `share_boundary_friction`, or `share_shear_strength` and "
              "`share_pressure_coefficient` | C_f's relative sensitivity to each parameter "
              "of the run's boundary law, d ln C_f / d ln q (they add up to "
              "`boundary_share`) |"]
    thermal = lambda key: " (`[thermal]`)" if "temperature" in key or "spot" in key else ""  # noqa: E731
    lines += [f"| `{header}` | {meaning}{thermal(key)} |"
              for key, (header, _, meaning) in OPTIONAL.items()]
    lines += ["",
              "## `results.nc`", "",
              "Group `stribeck`, over (viscosity [Pa s], speed [m/s]):", "",
              "| variable | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{k}` | {u} | {m} |" for k, (u, m) in UNITS.items()]
    lines += [f"| `{k}` | {u} | {m}{thermal(k)} |" for k, (_, u, m) in OPTIONAL.items()]
    lines += [f"| `{BOUNDARY_SHARE[0]}` | {BOUNDARY_SHARE[1]} | {BOUNDARY_SHARE[2]} |"]
    lines += ["| `cf_err` | 1 | estimated discretisation error of C_f |"]
    lines += [f"| `cf_err_{p}` | 1 | its {p} part |" for p in PARTS]
    lines += ["| `patch_friction_coefficient` | 1 | C_f with one patch's flow factors, over "
              "(patch, viscosity, speed) |", "",
              "Group `flow_factors`, over (patch: `\"1\"`, ..., `\"average\"`; h0 [m]): `h_m` "
              "[m], `p_con` [Pa], `contact_fraction`, `A11` ... `A22` (eq 13), `b1`, `b2` "
              "(eq 14), `C11` ... `C22` (eq 15), `d1`, `d2` (eq 16), the friction factors "
              "`sC`, `fP1`, `fP2`, and `film_fraction`, `log_sC` (the local shear's spread "
              "an Eyring film averages); NaN where a patch's "
              "adaptive sample skipped an h0.", "",
              "## `fields.nc`", "", "Over (viscosity, speed, x2 [m], x1 [m]):", "",
              "| variable | unit |", "|---|---|"]
    lines += [f"| `{k}` | {u} |" for k, u in FIELD_UNITS.items()]
    lines += ["", "## Older names", "", "Files of earlier versions are read with today's "
              "names:", "", "| then | now |", "|---|---|"]
    lines += [f"| `{old}` | `{new}` |" for old, new in LEGACY.items()]
    return "\n".join(lines) + "\n"


def generate(app, config=None) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, text in (("case_keys.md", case_keys()), ("cli.md", cli_reference()),
                       ("outputs.md", outputs())):
        path = OUT / name
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)


def check_gallery(app, exception) -> None:
    """Every numbered example of the gallery, when it ran, drew at least one figure (the
    examples' promise; tests/test_examples.py checks the same with ``-m slow``)."""
    conf = app.config.sphinx_gallery_conf
    if exception is not None or not conf.get("plot_gallery", True):
        return
    images = Path(app.srcdir) / "auto_examples" / "images"
    ran = conf.get("filename_pattern", "")
    missing = [p.stem for p in sorted(Path(conf["examples_dirs"]).glob("[0-9][0-9]_*.py"))
               if re.search(ran, str(p))
               and not (images / f"sphx_glr_{p.stem}_001.png").is_file()]
    if missing:
        raise RuntimeError(f"gallery examples without a figure: {missing}")


def setup(app):
    app.connect("config-inited", generate)
    app.connect("build-finished", check_gallery)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
