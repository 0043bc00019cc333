"""Regression tests of the twelfth hostile-input attack (issue 30) on the delimited-text
reader: quoted header fields, thousands grouped by a space or an apostrophe, integers grouped
by dots, and header units after a slash or in braces. Each test is named after the finding;
the files are small (no full run)."""

from __future__ import annotations

import pytest

from drillfric.errors import InputError
from drillfric.io.channels import map_channels
from drillfric.io.delimited import open_delimited, sniff_csv


def _write(path, lines, encoding="utf-8"):
    path.write_text("\n".join(lines) + "\n", encoding=encoding)
    return path


def _rows(path):
    return next(open_delimited(path).chunks(1000))


# ---------------------------------------------------------------- F3 quoted header fields
@pytest.mark.parametrize("header, hookload", [
    ('time_s,surface_rpm,surface_torque_Nm,"Hook load, avg",bit_depth_m,hole_depth_m',
     "Hook load, avg"),
    ('"Time, s","RPM, rpm","Torque, ft.lbf","Hookload, N","Bit Depth, m","Hole Depth, m"',
     "Hookload, N"),
])
def test_f3_a_quoted_header_field_holding_the_delimiter_keeps_the_columns_in_line(
        tmp_path, header, hookload):
    """'"Hook load, avg"' was split at its quoted comma: every later name moved one column
    right of its data (bit depth read from the hole-depth column, exit 0), and
    '"Bit Depth, m","Hole Depth, m"' became "duplicate column names". The header is read
    with CSV quoting, as pandas reads the rows."""
    path = _write(tmp_path / "q.csv", [header, "0.0,-0.1,-200,791504.34,2210.0,2215.0",
                                       "0.05,0.6,-80,794685.75,2210.0,2216.0"])
    layout = sniff_csv(path)
    assert len(layout.columns) == 6 and layout.columns[3] == hookload
    rows = _rows(path)
    assert list(rows.columns) == layout.columns
    assert rows.iloc[:, 4].tolist() == [2210.0, 2210.0]
    assert rows.iloc[:, 5].tolist() == [2215.0, 2216.0]
    mapped = map_channels(layout.columns, layout.units, {}, file=str(path))
    assert mapped["bit_depth"].column == layout.columns[4]
    assert mapped["hole_depth"].column == layout.columns[5]


def test_f3_a_unit_after_the_comma_of_a_quoted_name_is_the_header_unit():
    """'"Time, s"', '"Torque, ft.lbf"': the unit written after the comma is read as a
    trailing unit word is ("Average Surface Torque kN.m", docs/ingestion.md)."""
    columns = ["Time, s", "RPM, rpm", "Torque, ft.lbf", "Bit Depth, m"]
    mapped = map_channels(columns, {}, {}, file="w.csv")
    assert (mapped["time"].unit, mapped["time"].source) == ("s", "header")
    assert mapped["surface_torque"].unit == "ft.lbf"
    assert mapped["bit_depth"].unit == "m"


def test_f3_a_quoted_units_row_is_read_with_quoting(tmp_path):
    path = _write(tmp_path / "u.csv", ['TIME,"Hook load, avg",TORQUE', 's,"kN",kN.m',
                                       "0.0,791.5,1.2", "0.05,792.0,1.3"])
    layout = sniff_csv(path)
    assert layout.units_row and layout.units["Hook load, avg"] == "kN"
    assert layout.units["TORQUE"] == "kN.m"


# ---------------------------------------------------------------- F9 header unit forms
@pytest.mark.parametrize("columns", [
    ["TIME / s", "RPM / rpm", "TORQUE / ft.lbf"],
    ["TIME {s}", "RPM {rpm}", "TORQUE {ft.lbf}"],
    ["TIME s", "RPM rpm", "TORQUE ft.lbf"],
])
def test_f9_time_slash_s_and_time_in_braces_state_their_unit(columns):
    """'TIME / s' and 'TIME {s}' drew "assumed unit of time_s … nothing in the file or the
    config says" (both normalise to the mnemonic TIME_S, so the unit word was never looked
    at) while 'TORQUE / ft.lbf' was read. The unit the header states is read for every
    channel, braces like brackets."""
    mapped = map_channels(columns, {}, {}, file="w.csv")
    assert (mapped["time"].unit, mapped["time"].source) == ("s", "header")
    assert mapped["surface_torque"].unit.strip("{}") == "ft.lbf"
    assert mapped["surface_torque"].source == "header"


def test_f9_time_in_milliseconds_after_a_slash_is_milliseconds():
    mapped = map_channels(["TIME / ms", "RPM / rpm", "TORQUE / kN.m"], {}, {}, file="w.csv")
    assert mapped["time"].factor == pytest.approx(1e-3)
    assert mapped["surface_torque"].factor == pytest.approx(1e3)


# ---------------------------------------------------------------- F2 space/apostrophe groups
def _fr(value, group, mark=","):
    whole, frac = f"{value:,.2f}".split(".")
    return whole.replace(",", group) + mark + frac


@pytest.mark.parametrize("group, delimiter", [
    (" ", ";"), ("\u00a0", "\t"), ("\u202f", ";"), ("'", ";"), ("\u2019", ";")])
def test_f2_thousands_grouped_by_a_space_or_an_apostrophe_are_read(tmp_path, group,
                                                                    delimiter):
    """A decimal-comma log whose thousands are grouped by a space, a no-break space, a narrow
    no-break space or an apostrophe ('2 210,00'): every grouped value was read as missing, in
    silence — "the log has no bit depth" (it had one), μ_k 0.239 for 0.279, exit 0. A
    grouping character between groups of exactly 3 digits is removed."""
    lines = [delimiter.join(["time_s", "surface_rpm", "surface_torque_Nm", "hookload_N",
                             "bit_depth_m"])]
    for k in range(40):
        values = [_fr(0.05 * k, group), _fr(50.0, group), _fr(12420.0 + k, group),
                  _fr(791504.34, group), _fr(2210.0 + k, group)]
        lines.append(delimiter.join(values))
    path = _write(tmp_path / "fr.csv", lines)
    assert sniff_csv(path).decimal == ","
    from drillfric.io.well import open_well

    well = open_well(path)
    frame = next(well.chunks(1000))
    assert frame["bit_depth_m"].iloc[3] == pytest.approx(2213.0)
    assert frame["surface_torque_Nm"].iloc[1] == pytest.approx(12421.0)
    assert frame["hookload_N"].iloc[0] == pytest.approx(791504.34)
    assert frame["bit_depth_m"].notna().all() and frame["hookload_N"].notna().all()


@pytest.mark.parametrize("group, delimiter", [(" ", ","), ("'", ";"), ("'", ",")])
def test_f2_dot_decimal_with_a_space_or_apostrophe_grouping_is_read(tmp_path, group,
                                                                     delimiter):
    """'2 210.00' (English with a space) and the Swiss '2'210.00'."""
    lines = [delimiter.join(["TIME", "RPM", "TORQUE [N.m]", "BIT DEPTH [m]"])] + [
        delimiter.join([f"{0.05 * k:.2f}", "50.5", _fr(12420.0, group, "."),
                        _fr(2210.0 + k, group, ".")]) for k in range(20)]
    path = _write(tmp_path / "dot.csv", lines)
    assert sniff_csv(path).decimal == "."
    from drillfric.io.well import open_well

    frame = next(open_well(path).chunks(1000))
    assert frame["bit_depth_m"].iloc[2] == pytest.approx(2212.0)
    assert frame["surface_torque_Nm"].iloc[0] == pytest.approx(12420.0)


def test_f2_digits_split_by_a_space_that_groups_no_thousands_are_one_line(tmp_path):
    """'2 21,00' is no number drillfric can tell: one line naming the file, the column, the
    value and the grouping character (not a column read as missing)."""
    lines = ["time_s;surface_rpm;surface_torque_Nm;bit_depth_m"] + [
        f"{_fr(0.05 * k, ' ')};50,0;12,5;{'2 21,00' if k == 7 else '2 210,00'}"
        for k in range(20)]
    path = _write(tmp_path / "bad.csv", lines)
    from drillfric.io.well import open_well

    with pytest.raises(InputError, match=r"bad\.csv: column 'bit_depth_m' writes '2 21,00': "
                                         "digits split by a space that does not group"):
        next(open_well(path).chunks(1000))


def test_f2_a_time_of_1_234_s_grouped_by_a_space_is_read(tmp_path):
    """'999,00' then '1 000,00' s: the time column is read as text, its decimal commas and
    space groups both (it had been "cannot read '999,00' … as seconds")."""
    lines = ["time_s;surface_rpm;surface_torque_Nm"] + [
        f"{_fr(999.0 + k, ' ')};50,0;12,5" for k in range(5)]
    path = _write(tmp_path / "t.csv", lines)
    from drillfric.io.well import open_well

    frame = next(open_well(path).chunks(1000))  # from the first time on, 1 s apart
    assert frame["time_s"].tolist()[:3] == pytest.approx([0.0, 1.0, 2.0])


# ---------------------------------------------------------------- F4 integers grouped by dots
def _degrp(tmp_path, time):
    lines = ["Zeit;RPM;Torque [N.m];Hookload [N];Bit Depth [m]"] + [
        f"{time(k)};{k % 3};{-200 + 60 * k};" + f"{791504 + k:,};{2210 + k:,}".replace(",", ".")
        for k in range(30)]
    return _write(tmp_path / "degrp.csv", lines)


def test_f4_integers_grouped_by_dots_with_no_decimal_in_sight_are_one_line(tmp_path):
    """'791.504;2.210' with no decimal mark anywhere in the top: the dot was read as a
    decimal point — bit depth 2.21 m, torque 1000× low, "shorten the BHA sections". A dot
    before exactly 3 digits in every value of a column, with no other evidence, is refused
    naming the file, the column and both readings."""
    path = _degrp(tmp_path, lambda k: str(k))
    with pytest.raises(InputError, match=r"degrp\.csv: the decimal mark cannot be told: "
                                         r"column 'Hookload \[N\]' writes '791.504'.*791.504 "
                                         r"or 791504\?"):
        sniff_csv(path)


def test_f4_a_clock_time_with_a_decimal_comma_decides_the_file(tmp_path):
    """The attack's own file: its ISO times '12:00:00,050' write the decimal comma, so its
    dots group thousands (791 504 N, 2210 m)."""
    path = _degrp(tmp_path, lambda k: f"2024-05-01 12:00:{k:02d},050")
    assert sniff_csv(path).decimal == ","
    rows = _rows(path)
    assert rows["Bit Depth [m]"].iloc[0] == 2210 and rows["Hookload [N]"].iloc[1] == 791505


def test_f4_a_clock_time_with_a_decimal_dot_decides_the_file(tmp_path):
    path = _degrp(tmp_path, lambda k: f"2024-05-01 12:00:{k:02d}.050")
    assert sniff_csv(path).decimal == "."


def test_f4_ordinary_dot_decimal_semicolon_files_are_unchanged(tmp_path):
    """Values like 12.345 beside others of 1, 2 or 4 decimals: the dot is a decimal point."""
    lines = ["TIME;RPM;TORQUE;DEPTH"] + [
        f"{k};{50 + k * 0.1:.1f};12.345;{2210 + k * 0.25:.2f}" for k in range(30)]
    path = _write(tmp_path / "semidot.csv", lines)
    assert sniff_csv(path).decimal == "."
    assert _rows(path)["TORQUE"].iloc[0] == pytest.approx(12.345)


def test_f4_two_dot_groups_show_a_thousands_dot(tmp_path):
    lines = ["TIME;HKLD;DEPTH"] + [f"{k};1.791.504;2.210" for k in range(10)]
    path = _write(tmp_path / "dots.csv", lines)
    assert sniff_csv(path).decimal == ","
    assert _rows(path)["DEPTH"].iloc[0] == 2210


# ---------------------------------------------------------------- the survey reader too
@pytest.mark.parametrize("header, row", [
    ('"MD, m","Inc, deg","Azi, deg"', "{md:.1f},{inc:.2f},{azi:.2f}"),
    ('"MD, m";"Inc, deg";"Azi, deg"', "{md_fr};{inc_fr};{azi_fr}"),
])
def test_f2_f3_a_survey_with_quoted_names_and_grouped_depths_is_read(tmp_path, header, row):
    """The survey reader split its header at a quoted comma too, and refused '2 210,00'."""
    from drillfric.io.survey import read_survey_table

    stations = [(0.0, 0.0, 0.0), (1000.0, 0.0, 0.0), (1500.0, 50.0, 30.0),
                (2430.0, 50.0, 30.0)]
    lines = [header] + [row.format(md=md, inc=inc, azi=azi, md_fr=_fr(md, " "),
                                   inc_fr=_fr(inc, " "), azi_fr=_fr(azi, " "))
                        for md, inc, azi in stations]
    table = read_survey_table(_write(tmp_path / "s.csv", lines))
    assert table.iloc[:, 0].tolist() == pytest.approx([0.0, 1000.0, 1500.0, 2430.0])
    assert table.iloc[2, 1] == pytest.approx(50.0)


def test_f4_the_decimal_mark_is_voted_on_beyond_the_first_50_lines(tmp_path):
    """A German log whose first dotted value ('1.050' N·m) comes at line 80, well inside the
    64 KiB the layout is sniffed from, with a decimal comma at line 120: the comma decides."""
    lines = ["TIME;RPM;TORQUE"] + [
        f"{k};50;{'1.050' if k >= 80 else 900}{',5' if k == 120 else ''}" for k in range(200)]
    path = _write(tmp_path / "late.csv", lines)
    assert sniff_csv(path).decimal == ","
    assert _rows(path)["TORQUE"].iloc[100] == 1050


@pytest.mark.parametrize("unit, scale", [("FTLB", 1.0), ("ft lb", 1.0), ("lb.ft", 1.0),
                                         ("ft.lbs", 1.0), ("kft.lb", 1e3), ("klb.ft", 1e3)])
def test_torque_written_with_lb_for_the_pound_of_force(unit, scale):
    """Noticed during the twelfth attack: `FTLB` (pint: femto-troy-pounds), `lb.ft`,
    `ft lb`, `ft.lbs`, `klb.ft`, `kft.lb` refused the log with exit 2 while `ft.lb` and
    `kftlb` were read. On a torque channel "lb" is the pound of force (1 ft·lbf =
    1.3558179483 N·m, exact)."""
    from drillfric.io.channels import BY_KEY, factor

    assert factor(unit, BY_KEY["surface_torque"]) == pytest.approx(
        scale * 0.3048 * 4.4482216152605)
