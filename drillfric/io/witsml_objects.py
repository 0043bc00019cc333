"""WITSML 1.4.1 (and 1.3.1) trajectories and tubulars: the survey and the string of a well.

A ``<trajectory>`` becomes the canonical survey table (:func:`trajectory_table`: md, inc,
azi and, where given, tvd, dispNs, dispEw, dls in the units of each ``uom``), read by
:func:`drillfric.io.survey.read_survey_table` for ``.xml`` surveys; a ``<tubular>`` becomes
``[[string.sections]]`` tables, top-down (:func:`tubular_sections`). Files are parsed as in
:mod:`drillfric.io.witsml` (defusedxml, no DTD); every failure is an InputError naming the
file.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pint

from drillfric.errors import InputError
from drillfric.io.witsml import (
    FIX_EXPORT,
    check_namespace,
    local_name,
    measure,
    object_kind,
    parse_int,
    parse_tree,
    text_of,
    unit_factor,
)
from drillfric.units import conversion_factor, parse_unit, registry

#: Trajectory station states whose station is not used.
_BAD_STATIONS = frozenset({"bad", "rejected"})


# --------------------------------------------------------------------------- trajectory
def _stations(trajectory, path: Path) -> pd.DataFrame:
    """Stations of one ``<trajectory>`` in canonical columns (md_m, inc_deg, azi_deg …)."""
    rows = []
    for station in (s for s in trajectory if local_name(s.tag) == "trajectoryStation"):
        if (text_of(station, "statusTrajStation") or "").lower() in _BAD_STATIONS:
            continue
        row = {}
        for name, column, kind in (("md", "md_m", "length"), ("incl", "inc_deg", "angle"),
                                   ("azi", "azi_deg", "angle"), ("tvd", "tvd_m", "length"),
                                   ("dispNs", "north_m", "length"),
                                   ("dispEw", "east_m", "length")):
            found = measure(station, name, path, required=column in ("md_m", "inc_deg",
                                                                       "azi_deg"))
            if found is not None:
                value = found[0] * unit_factor(found[1], kind, f"station {name}", path)
                row[column] = np.degrees(value) if kind == "angle" else value
        dls = measure(station, "dls", path, required=False)
        if dls is not None and _dls_factor(dls[1]) is not None:
            row["dls_deg_30m"] = dls[0] * _dls_factor(dls[1])
        rows.append(row)
    table = pd.DataFrame(rows)
    optional = [c for c in ("tvd_m", "north_m", "east_m", "dls_deg_30m")
                if c in table and table[c].notna().all()]
    if table.empty:
        return table
    return table[["md_m", "inc_deg", "azi_deg", *optional]].sort_values(
        "md_m", kind="stable").reset_index(drop=True)


def _dls_factor(uom: str) -> float | None:
    """°/30 m per unit of a dogleg-severity uom (``rad/m``, ``dega/30m``, ``dega/100ft``).

    Examples
    --------
    >>> round(_dls_factor("dega/100ft"), 4)
    0.9843
    """
    match = re.fullmatch(r"\s*([A-Za-z]+)\s*/\s*([0-9.]*)\s*([A-Za-z]+)\s*", uom)
    if match is None:
        return None
    try:
        angle = np.degrees(conversion_factor(match[1], "angle"))
        per = float(match[2] or 1.0) * conversion_factor(match[3], "length")
    except (InputError, ValueError):
        return None
    return float(angle * 30.0 / per)


def trajectory_table(path) -> pd.DataFrame:
    """The stations of a WITSML trajectory as a canonical survey table.

    Columns ``md_m`` [m], ``inc_deg`` [°], ``azi_deg`` [°], and ``tvd_m``, ``north_m``,
    ``east_m`` [m], ``dls_deg_30m`` [°/30 m] when every station has them, sorted by MD.
    Units come from each measure's ``uom`` (``m``, ``ft``, ``rad``, ``dega`` …). Stations
    marked ``bad`` or ``rejected`` are left out. Several trajectories in one file: the
    deepest is read. Validation (increasing MD, angle ranges) is the survey reader's.

    Raises
    ------
    InputError
        Unsafe or malformed XML, no trajectory, a station without md/incl/azi or uom.
    """
    path = Path(path)
    root = parse_tree(path)
    check_namespace(root, path)
    found = [t for t in root.iter() if local_name(t.tag) == "trajectory"]
    if not found:
        raise InputError(f"WITSML file holds {object_kind(path)} objects, not a trajectory",
                         file=path, fix="give a WITSML trajectory (or a survey table)")
    tables = [_stations(t, path) for t in found]
    best = max(tables, key=lambda t: (t["md_m"].max() if len(t) else -np.inf, len(t)))
    if best.empty:
        raise InputError("WITSML trajectory has no stations", file=path,
                         fix="export the trajectory with its trajectoryStation elements")
    return best


# --------------------------------------------------------------------------- tubular
def _component(comp, path: Path) -> dict:
    """One ``tubularComponent`` as a ``[[string.sections]]`` table."""
    od = measure(comp, "od", path)
    inner = measure(comp, "id", path)
    length = measure(comp, "len", path)
    od_m = od[0] * unit_factor(od[1], "length", "tubularComponent od", path)
    section = {"name": "", "od_m": od_m,
               "id_m": inner[0] * unit_factor(inner[1], "length", "tubularComponent id", path),
               "length_m": length[0] * unit_factor(length[1], "length",
                                                    "tubularComponent len", path)}
    kind = text_of(comp, "typeTubularComp") or "component"
    section["name"] = f"{kind} {od_m / 0.0254:.4g}in"
    if section["length_m"] <= 0 or not 0 <= section["id_m"] < od_m:
        raise InputError(f"tubular component '{section['name']}' has length "
                         f"{section['length_m']:g} m, OD {od_m:g} m, ID {section['id_m']:g} m "
                         "(needs length > 0 and 0 ≤ ID < OD)", file=path, fix=FIX_EXPORT)
    mass = measure(comp, "wtPerLen", path, required=False)
    if mass is not None and mass[0] > 0:
        section["linear_mass_kg_m"] = _linear_mass(mass, path)
    joints = [measure(c, "od", path, required=False) for c in comp
              if local_name(c.tag) == "connection"]
    joint_od = max((j[0] * unit_factor(j[1], "length", "connection od", path)
                    for j in joints if j is not None), default=0.0)
    if joint_od > od_m:
        section["tool_joint_od_m"] = joint_od
    return section


def _linear_mass(given: tuple[float, str], path: Path) -> float:
    try:
        return float(registry().Quantity(given[0], parse_unit(given[1])).to("kg/m")
                     .magnitude)
    except (InputError, pint.errors.DimensionalityError) as exc:
        raise InputError(f"tubularComponent wtPerLen unit '{given[1]}' is not a mass per "
                         "length", file=path, fix=FIX_EXPORT) from exc


def tubular_sections(path, *, uid: str | None = None) -> list[dict]:
    """A WITSML tubular (the drill string) as ``[[string.sections]]`` tables, top-down.

    WITSML numbers components by ``sequence`` in the order they entered the hole (1 first,
    i.e. at the bit), so the top-down order is by decreasing sequence; components without
    a sequence keep their document order, read as the order they entered the hole.
    Each table has ``name`` (component type and OD in inches), ``od_m``, ``id_m``,
    ``length_m`` [m], and ``linear_mass_kg_m`` [kg/m] (from ``wtPerLen``) and
    ``tool_joint_od_m`` [m] (the largest ``connection/od`` above the body OD) when the file
    gives them. Every section has its length; the configuration lets the top one's length
    follow from the bit depth instead (drop its ``length_m`` for that).

    Parameters
    ----------
    path : str or Path
        WITSML file holding ``<tubular>`` objects.
    uid : str, optional
        uid or name of the tubular when the file holds several.

    Raises
    ------
    InputError
        Unsafe or malformed XML, no tubular (or several and no ``uid``), a component
        without od/id/len, or with impossible dimensions.
    """
    path = Path(path)
    root = parse_tree(path)
    check_namespace(root, path)
    tubulars = [t for t in root.iter() if local_name(t.tag) == "tubular"
                and (uid is None or uid in (t.get("uid"), text_of(t, "name")))]
    if len(tubulars) != 1:
        problem = ("no tubular" if not tubulars else f"{len(tubulars)} tubulars")
        raise InputError(f"WITSML file holds {problem}" + ("" if uid is None else
                                                           f" with uid or name '{uid}'"),
                         file=path, fix="give a file with one tubular, or its uid")
    comps = [c for c in tubulars[0] if local_name(c.tag) == "tubularComponent"]
    if not comps:
        raise InputError("WITSML tubular has no tubularComponent", file=path, fix=FIX_EXPORT)
    entered = sorted(range(len(comps)),
                     key=lambda i: (parse_int(text_of(comps[i], "sequence"), 0), i))
    return [_component(comps[i], path) for i in reversed(entered)]
