"""Every field of the C++ option/summary structs is reachable from Python.

The fields are read from the C++ headers themselves, so a field added in C++
without its binding line (python/src/module.cc) fails here."""

import os
import re

import pytest

import ceres_sesync as cs
from conftest import SOURCE_DIR

# (header, C++ struct, Python class).
STRUCTS = [
    ("sesync_solver.h", "SolverOptions", cs.SolverOptions),
    ("sesync_solver.h", "SolverSummary", cs.SolverSummary),
    ("sesync_solver.h", "Level", cs.SolverSummary.Level),
    ("sesync_solver.h", "SolverProgress", cs.SolverProgress),
    ("certification.h", "CertifyOptions", cs.CertifyOptions),
    ("certification.h", "Certificate", cs.Certificate),
    ("component_solver.h", "ComponentsSummary", cs.ComponentsSummary),
    ("component_solver.h", "Component", cs.ComponentsSummary.Component),
    ("component_solver.h", "PoseGraphComponent", cs.PoseGraphComponent),
    ("cube_generator.h", "CubeOptions", cs.CubeOptions),
    ("city_generator.h", "CityOptions", cs.CityOptions),
    ("landmark_generator.h", "LandmarkGraphOptions", cs.LandmarkGraphOptions),
    ("g2o_io.h", "G2oReadOptions", cs.G2oReadOptions),
    ("g2o_io.h", "G2oReadSummary", cs.G2oReadSummary),
    ("pose_graph.h", "PoseGraph", cs.PoseGraph),
    ("robust_solver.h", "RobustSolverOptions", cs.RobustSolverOptions),
    ("robust_solver.h", "RobustSolverSummary", cs.RobustSolverSummary),
    ("robust_solver.h", "Edge", cs.RobustSolverSummary.Edge),
    ("robust_solver.h", "Iteration", cs.RobustSolverSummary.Iteration),
    ("robust_solver.h", "Run", cs.RobustSolverSummary.Run),
    ("pose_graph.h", "RelativePoseMeasurement", cs.Measurements),
]


def struct_body(text, name):
    match = re.search(r"\bstruct\s+" + name + r"\s*\{", text)
    assert match, f"struct {name} not found"
    depth, k = 1, match.end()
    start = k
    while depth:
        depth += {"{": 1, "}": -1}.get(text[k], 0)
        k += 1
    return text[start : k - 1]


def remove_nested(text, open_, close):
    """Removes balanced open_...close groups, replacing each by `;`-free
    text (braces by ';' so that an inline function body ends its declaration)."""
    out, depth = [], 0
    for ch in text:
        if ch == open_:
            depth += 1
            continue
        if ch == close:
            depth -= 1
            if depth == 0 and open_ == "{":
                out.append(";")
            continue
        if depth == 0:
            out.append(ch)
    return "".join(out)


def declared_fields(header, name):
    text = open(os.path.join(SOURCE_DIR, "ceres_sesync", header)).read()
    body = re.sub(r"//[^\n]*", "", struct_body(text, name))
    body = remove_nested(body, "{", "}")  # nested structs/enums, inline bodies
    body = remove_nested(body, "<", ">")  # template arguments
    names = []
    for declaration in body.split(";"):
        declaration = " ".join(declaration.split())
        if not declaration or re.match(r"(enum|struct|class|using|friend|static)\b", declaration):
            continue
        declaration = re.sub(r"^(public|private|protected):", "", declaration).strip()
        parts, depth, current = [], 0, ""
        for ch in declaration:  # split at top-level commas
            depth += {"(": 1, ")": -1}.get(ch, 0)
            if ch == "," and depth == 0:
                parts.append(current)
                current = ""
            else:
                current += ch
        parts.append(current)
        parts = [p.split("=")[0].strip() for p in parts]
        if any("(" in p for p in parts):
            continue  # a member function
        names += [re.findall(r"\w+", p)[-1] for p in parts]
    return names


def test_the_header_parser_finds_known_fields():
    # The parser must be able to find fields, or the test below proves nothing.
    summary = declared_fields("sesync_solver.h", "SolverSummary")
    for field in ["status", "num_poses", "num_measurements", "levels", "rounding_time_s"]:
        assert field in summary
    assert "certified" not in summary and "BriefReport" not in summary and "Level" not in summary
    options = declared_fields("sesync_solver.h", "SolverOptions")
    assert "callback" in options and "progress" in options and "kChordal" not in options
    assert len(options) >= 24


@pytest.mark.parametrize("header,struct,cls", STRUCTS, ids=[s[1] for s in STRUCTS])
def test_every_field_is_bound(header, struct, cls):
    fields = declared_fields(header, struct)
    assert fields
    missing = [f for f in fields if f not in cls._fields]
    assert not missing, f"{struct} fields without a binding in python/src/module.cc: {missing}"
    for name in cls._fields:
        assert hasattr(cls, name), name
