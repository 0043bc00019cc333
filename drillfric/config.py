"""Well configuration: one declarative schema, a validating TOML loader, precedence.

Every key of the well configuration file (``NAME.toml`` / ``well.toml``, see
docs/configuration.md) is declared once in :data:`SCHEMA` with its type, unit, default, allowed
range and help text. The loader validates types and ranges and rejects unknown keys by
name and file; ``docs/configuration.md`` is generated from the same declaration
(:func:`schema_markdown`, checked by ``tests/test_config.py``).

Precedence: command line > config file > defaults (:func:`load_config` ``overrides``).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, make_dataclass
from pathlib import Path
from typing import Any

from drillfric.errors import ConfigError
from drillfric.files import require_file

_NUM = (int, float)
#: Largest physically plausible value of a key by its unit suffix, where the key declares no
#: maximum of its own: a value beyond is a typo or a wrong unit (a top-drive inertia of 1e300
#: gives a confident μ_k of 0.01). Generous on purpose: the deepest wells are ~12 km, the
#: heaviest top drives ~1e4 kg·m², the stiffest steels ~2e11 Pa.
_PLAUSIBLE_MAX = (("_deg_30m", 30.0), ("_kg_m2", 1e5), ("_kg_m3", 25e3), ("_kg_m", 2e3),
                  ("_Nms_rad", 1e9), ("_Nm_rad", 1e9), ("_Nm", 1e7), ("_Pa", 1e12),
                  ("_N", 1e8), ("_m3_s", 10.0), ("_m_s", 100.0), ("_m_h", 1e3),
                  ("_rad_s", 100.0), ("_rpm", 1e3), ("_per_s", 1e4), ("_hz", 1e5),
                  ("_spm", 1e3), ("_s", 1e7), ("_m", 15e3))


@dataclass(frozen=True)
class Key:
    """One configuration key.

    Attributes
    ----------
    name : str
        Key name inside its table, with its unit as suffix (``mud_density_kg_m3``).
    type : type or tuple of types
        Accepted TOML value types (``float`` keys accept integers).
    default : Any
        Value used when the key is absent (``None``: no default, optional).
    unit : str
        Unit in words for the documentation ("" for dimensionless / text).
    help : str
        One-line description.
    min, max : float, optional
        Inclusive numeric range (``min_exclusive`` for strictly positive values).
    choices : tuple, optional
        Allowed values for text keys.
    """

    name: str
    type: Any
    default: Any
    unit: str
    help: str
    min: float | None = None
    max: float | None = None
    min_exclusive: bool = False
    choices: tuple | None = None
    #: ((low, high, unit), …): a bare number in [low, high] is taken for one in ``unit`` (a
    #: mud density of 1.25 is a specific gravity, not 1.25 kg/m³) and refused, with the fix
    bare_units: tuple = ()

    @property
    def upper(self) -> float | None:
        """Largest allowed value: ``max``, else the plausible maximum of the unit suffix."""
        if self.max is not None or self.type not in (float, int):
            return self.max
        return next((top for suffix, top in _PLAUSIBLE_MAX if self.name.endswith(suffix)),
                    None)

    def validate(self, value: Any, where: str, file: str | None) -> Any:
        """Return ``value`` checked (and ints widened to float) or raise ConfigError.

        A number with a unit, written as text (``"10.5 ppg"``, ``"5 1/2 in"``), is accepted
        for a key with a unit and converted exactly to it
        (:func:`drillfric.units.quantity_value`); a unit of another dimension is an error
        naming the key, the file and the quantity expected.
        """
        types = self.type if isinstance(self.type, tuple) else (self.type,)
        written = ""
        if isinstance(value, str) and float in types and str not in types and self.unit:
            from drillfric.units import quantity_value

            text = "".join(c if c.isprintable() else "?" for c in value.strip()[:40])
            written = f" ('{text}')"
            value = quantity_value(value, self.unit, what=f"key '{where}'", file=file)
        if not written and isinstance(value, (int, float)) and not isinstance(value, bool):
            self._check_bare(value, where, file)
        if float in types and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if isinstance(value, bool) and bool not in types or not isinstance(value, types):
            wanted = " or ".join(_TYPE_NAMES.get(t, t.__name__) for t in types)
            raise ConfigError(f"key '{where}' must be {wanted}, got {value!r}", file=file,
                              fix=f"write e.g. {where.split('.')[-1]} = {_example(self)}")
        if self.choices is not None and value not in self.choices:
            raise ConfigError(f"key '{where}' must be one of {', '.join(map(repr, self.choices))}"
                              f", got {value!r}", file=file,
                              fix=f"write e.g. {where.split('.')[-1]} = {_example(self)}")
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            if not math.isfinite(value):
                raise ConfigError(f"key '{where}' = {value} is not a finite number", file=file,
                                  fix=f"write e.g. {where.split('.')[-1]} = {_example(self)}")
            low_bad = self.min is not None and (
                value <= self.min if self.min_exclusive else value < self.min)
            if low_bad or (self.upper is not None and value > self.upper):
                raise ConfigError(f"key '{where}' = {value:.4g}{written} is outside "
                                  f"{self.range_text()}", file=file,
                                  fix=f"give a value {self.range_text()}"
                                      + (f" [{self.unit}]" if self.unit else ""))
        return value

    def _check_bare(self, value: float, where: str, file: str | None) -> None:
        """Refuse a bare number that reads as one in another unit (:attr:`bare_units`): a
        mud density of ``1.25`` or ``10.4`` had been taken as kg/m³ — a string in a gas —
        and put μ_k 15 % low with exit 0 (issue 30, twelfth attack)."""
        for low, high, unit in self.bare_units:
            if low <= value <= high:
                raise ConfigError(
                    f"key '{where}' = {value:g} [{self.unit}] is no drilling mud (water is "
                    f"1000 kg/m³): is it in {unit}?", file=file,
                    fix=f'write {where.split(".")[-1]} = "{value:g} {unit}" (or '
                        f'"{value:g} kg/m3" for a gas)')

    def range_text(self) -> str:
        """Allowed range in words, e.g. ``(0, 2]`` or ``≥ 0``."""
        top = self.upper
        if self.min is None and top is None:
            return ""
        lo = "" if self.min is None else ("(" if self.min_exclusive else "[") + f"{self.min:g}"
        if top is None:
            return ("> " if self.min_exclusive else "≥ ") + f"{self.min:g}"
        if self.min is None:
            return f"≤ {top:g}"
        return f"{lo}, {top:g}]"


#: Bare mud densities that are a specific gravity or pounds per gallon without their unit.
_MUD_BARE = ((0.5, 3.0, "sg"), (6.0, 25.0, "ppg"))

_TYPE_NAMES = {float: "a number", int: "an integer", str: "text", bool: "true/false",
               list: "a list", dict: "a table"}


def _example(key: Key) -> str:
    if key.choices:
        return repr(key.choices[0]).replace("'", '"')
    if key.default is not None:
        return repr(key.default).replace("'", '"').replace("True", "true").replace(
            "False", "false")
    return {float: "1.0", int: "1", str: '"..."', list: "[]"}.get(
        key.type if not isinstance(key.type, tuple) else key.type[0], "...")


def _positive(name, default, unit, help_, **kw):
    return Key(name, float, default, unit, help_, min=0.0, min_exclusive=True, **kw)


#: Table name -> keys. ``string.sections`` is an array of tables with :data:`SECTION_KEYS`.
SCHEMA: dict[str, tuple[Key, ...]] = {
    "well": (
        Key("name", str, None, "", "Well name used in outputs (default: the data file's stem)."),
        Key("data", str, None, "", "Surface data file, relative to the config "
            "(directory wells: well.toml names its files)."),
        Key("bit_depth_m", float, None, "m", "Bit depth of every segment when the log has no "
            "bit-depth channel (and no block reckoning): a single stand or a test at one "
            "depth. Default: the survey's last station, announced as assumed.", min=0.0,
            min_exclusive=True),
        Key("bit_diameter_m", float, None, "m", "Bit diameter D_bit of the well's time log: "
            "with it, on-bottom segments report the bit friction coefficient μ_bit = "
            "3·T_bit/(WOB·D_bit) and the downhole mechanical specific energy beside the bit "
            "torque (docs/theory.md §2.3). Default: none, those two are null with the reason.",
            min=0.0, min_exclusive=True, max=1.5),
        Key("units", str, "si", "", "Units people read: terminal summaries (run, td, inspect) "
            "and report axes and tables — 'si' (m, kN, kN·m, kg/m³) or 'field' (ft, klbf, "
            "kft·lbf, ppg, in); --units overrides. Result files (Parquet, JSON) stay SI.",
            choices=("si", "field")),
    ),
    "survey": (
        Key("file", str, None, "", "Survey file (MD, inclination, azimuth), relative to the "
            "config. Without a survey the well is assumed vertical, with the nominal "
            "tortuosity below."),
        Key("tortuosity_deg_30m", float, 1.0, "°/30 m", "Nominal tortuosity of the path "
            "assumed when there is no survey: a vertical hole wound into a helix (300 m "
            "period) whose dogleg severity is this everywhere, so the string gets side force "
            "(docs/torque_drag.md). An assumption: friction factors then scale about as "
            "1/tortuosity and are indicative. 0 = exactly vertical (no side force: rotating "
            "segments are skipped). Ignored when a survey is given.", min=0.0, max=10.0),
        _positive("max_dogleg_deg_30m", 30.0, "°/30 m", "Largest dog-leg severity a survey "
                  "station may show: beyond it the survey is refused as a suspected typo (an "
                  "inclination of 5 for 50 bends the path 45°/30 m on each side and printed "
                  "μ_k 35 % low); conventional wells stay below 10–15°/30 m. Raise it for a "
                  "short-radius well.", max=300.0),
    ),
    "fluid": (
        Key("mud_density_kg_m3", float, 1200.0, "kg/m³", "Mud density in the annulus "
            "(outside the string). A bare number of 0.5–3 or 6–25 is refused as a specific "
            "gravity or ppg written without its unit (write \"1.25 sg\").", min=0.0,
            max=7849.0, bare_units=_MUD_BARE),
        Key("inner_mud_density_kg_m3", float, None, "kg/m³", "Mud density inside the string "
            "(default: same as mud_density_kg_m3).", min=0.0, max=7849.0,
            bare_units=_MUD_BARE),
    ),
    "rig": (
        Key("top_drive_inertia_kg_m2", float, 2900.0, "kg·m²", "Top-drive rotating inertia "
            "I_TD (A&S 2018 measured 2900; real drives 300–10 000: below 10 the observer's "
            "inertia correction diverges).", min=10.0),
        Key("torque_kind", str, "motor", "", "What the logged surface torque is: 'motor' "
            "(drive torque τ_m) or 'string' (already inertia-corrected, τ(0) = τ_m − I_TD "
            "dω₀/dt).", choices=("motor", "string")),
        _positive("sample_averaging_s", None, "s", "Each logged sample is the mean over this "
                  "interval (EDR-style 1-s or 5-s averages); default: spot values. With the "
                  "sample interval it decides whether the stick-slip cycle — and so the bit "
                  "speed — is resolved (docs/bit_speed.md)."),
    ),
    "bha": (
        Key("motor_rev_per_litre", float, None, "rev/L", "Mud motor (positive displacement "
            "motor) in the BHA: its no-load speed per unit of flow in, k (spec sheets: "
            "0.03–0.3 rev/L; \"0.15 rev/gal\" accepted). With it, and the flow channel, "
            "the bit turns at the string's bottom speed plus k·flow (docs/theory.md §2.4): "
            "bit_rpm_est gains the motor's speed, bha_rpm_est keeps the string's. Default: "
            "no motor.", min=0.0, min_exclusive=True, max=10.0),
        Key("motor_speed_drop", float, 0.3, "", "Largest share of its no-load speed a "
            "declared motor loses under the bit's load on bottom (a PDM at its full "
            "recommended differential pressure turns 15–30 % slower): the on-bottom motor "
            "speed is taken as the middle of k·flow·[1 − drop, 1], the MSE's speed "
            "uncertainty spans the range (docs/theory.md §2.4).", min=0.0, max=0.9),
    ),
    "model": (
        Key("omega_c_rad_s", float, None, "rad/s", "Static/kinetic switching speed ω_c "
            "(default 1.0 rad/s; give this or omega_c_rpm).", min=0.0, min_exclusive=True),
        Key("omega_c_rpm", float, None, "RPM", "Static/kinetic switching speed ω_c in RPM "
            "(alternative to omega_c_rad_s).", min=0.0, min_exclusive=True),
        Key("k_t_per_s", float, 0.1, "1/s", "Viscous damping rate k_t of the torsional "
            "model (docs/theory.md §3, eq. 2–3).", min=0.0),
        Key("k_t_uncertainty_factor", float, 3.0, "", "How far the true viscous damping "
            "may lie from k_t_per_s, as a factor f (k_t/f … f·k_t; heavy mud reached 3×): "
            "μ_k's 95 % interval carries what that range moves it by where this exceeds the "
            "validated tolerance (docs/theory.md §6.4 \"Uncertainty of μ_k\"); 1 trusts "
            "k_t_per_s as given.", min=1.0, max=100.0),
        Key("cells", int, 500, "", "Number of cells of the torsional model (the paper: 500).",
            min=20, max=200000),
        _positive("element_length_m", 2.0, "m", "Element length of the soft-string "
                  "torque-and-drag march (docs/theory.md §2).", max=30.0),
        Key("friction", float, 0.25, "", "Friction factor used by torque-and-drag when no "
            "other is given (td without --friction).", min=0.0, max=2.0),
        Key("casing_shoe_md_m", float, None, "m", "Measured depth of the last casing shoe; "
            "with friction_cased (or friction_ratio_cased) the friction differs above and "
            "below it, and the estimated factors are the open hole's (docs/theory.md §3.2).",
            min=0.0),
        Key("friction_cased", float, None, "", "Kinetic friction factor inside casing, known "
            "from the previous section: torque and drag use it above the shoe, and the "
            "estimator holds it fixed there and estimates the open-hole factors.",
            min=0.0, max=2.0),
        Key("friction_cased_static", float, None, "", "Static friction factor inside casing, "
            "when known (≥ friction_cased). Unknown, a μ_s is reported for the open hole only "
            "when it holds both with the open hole's static/kinetic ratio and with none.",
            min=0.0, max=2.0),
        Key("friction_ratio_cased", float, None, "", "Cased friction as a ratio of the open "
            "hole's, μ_cased/μ_open (instead of friction_cased): the estimated factors are "
            "the open hole's, the cased part scaled by the ratio.", min=0.0, max=10.0,
            min_exclusive=True),
        Key("friction_open", float, None, "", "T&D friction factor in open hole (td and the "
            "broomstick; the estimator estimates it).", min=0.0, max=2.0),
        Key("friction_law", str, "step", "", "Friction law of the estimator's models: 'step' "
            "(μ_s below ω_c, μ_k above: the paper) or 'stribeck' (μ falls from μ_s at rest to "
            "μ_k with stribeck_speed_rad_s, docs/theory.md §3.2).",
            choices=("step", "stribeck")),
        _positive("stribeck_speed_rad_s", None, "rad/s", "Decay speed v_s of the Stribeck "
                  "law (with friction_law = 'stribeck')."),
        Key("stribeck_exponent", float, 1.0, "", "Exponent δ of the Stribeck law "
            "exp(−(|ω|/v_s)^δ): 1 exponential, 2 Gaussian.", min=1.0, max=2.0),
    ),
    "observer": (
        Key("gains", str, "kalman", "", "Gain design: steady-state 'kalman' (default; far less "
            "driven by measurement noise, docs/validation.md) or the closed-form "
            "'backstepping' of docs/theory.md §5.1.", choices=("backstepping", "kalman")),
        Key("law", str, "corrected", "", "Adaptation law: 'corrected' (drillfric) or 'paper' "
            "(eqs. 42–43 exactly as printed, for comparison).", choices=("corrected", "paper")),
        Key("kappa1", float, 1.0, "", "Fraction κ₁ of the top-side reflection cancelled "
            "(0 < κ₁ < 2: the design needs it strictly below 2).",
            min=0.0, max=1.99, min_exclusive=True),
        _positive("lambda0_per_s", 10.0, "1/s", "Bandwidth λ₀ of the top-drive injection."),
        Key("poles_per_s", list, [1.0, 1.5], "1/s", "The two poles z, p placed for the "
            "downhole error (ω_L, d)."),
        Key("starts", list, [[0.3, 0.2], [0.6, 0.4], [0.9, 0.1]], "", "Initial guesses "
            "[[μ_s, μ_k], ...] advanced together in one pass."),
        _positive("mu_max", 1.5, "", "Physical clamp on the estimated friction factors: the "
                  "observer's and every search of the batch fit (μ_k, the creep μ_s, the "
                  "stick-slip-onset scan). The starts must lie within it."),
        Key("interpolation", str, "linear", "", "Measurements between samples: 'linear' "
            "(default, one sample of lag) or 'hold' (the paper's zero-order hold).",
            choices=("linear", "hold")),
        _positive("output_rate_hz", 10.0, "Hz", "Rate of estimates.parquet rows (at most "
                  "1000 Hz: ten times the fastest rig logs; rows cost memory per segment).",
                  max=1000.0),
        _positive("speed_noise_rpm", 0.5, "RPM", "Standard deviation of the logged top-drive "
                  "speed's noise per sample; with the logging interval it sets the Kalman "
                  "design's measurement noise. At most 5 RPM (a speed sensor's noise; "
                  "quantised to 1 RPM it is 0.3): set far above the log's noise the observer "
                  "ignores the speed it is given (1000 had drawn a bit trace 54 RPM RMS from "
                  "the bit, shown as resolved).", max=5.0),
        _positive("starts_window_s", 300.0, "s", "The starts run together over this first part "
                  "of each segment (they converge within it); the seeded pass covers all."),
        _positive("deadlock_s", 15.0, "s", "Deadlock guard: an estimated BHA stuck this long "
                  "while the top drive turns releases μ̂_s to μ̂_k (docs/theory.md §6.1)."),
        Key("ensemble_members", int, 5, "", "Members of the final pass seeded with the "
            "batch-refined factors; the estimated bit speed is their mean and min–max its "
            "band (the stick-slip cycle is chaotic: members drift apart in phase; weighted by "
            "how well each matches the surface speed lately, their mean tracks the bit better "
            "than any one, docs/bit_speed.md). 1 = a single observer (μ̂ held unless "
            "adapt_final).",
            min=1, max=32),
        Key("ensemble_spread", float, 0.15, "", "Relative half-width of μ_s across the "
            "ensemble members: μ_s·(1 ± spread), the uncertainty of the refined μ_s.",
            min=0.0, max=0.5),
        Key("adapt_final", bool, False, "", "Keep adapting μ̂ in the final pass. Off by "
            "default: the batch factors are the better estimates (±2 % vs ±10 %, "
            "docs/theory.md §6) and adaptation through a creep break-over can drive μ̂_k to "
            "μ_s."),
    ),
    "batch": (
        Key("window_s", float, 600.0, "s", "The batch refinement (docs/theory.md §6.4) fits "
            "the first this-many seconds of each segment (the mean-torque match needs "
            "minutes; creep start-ups are at the start). At least 10 s: a shorter window "
            "holds less than one stick-slip cycle.", min=10.0),
        Key("trend_window_s", float, 120.0, "s", "Window of the re-fits that give μ_k(t) over "
            "the whole segment (windows overlap by half; docs/theory.md §6.6): friction that "
            "moves within a stand is tracked at this resolution, a change faster than it is "
            "withheld. Shorter windows hold fewer torque cycles (a larger stated "
            "uncertainty).", min=30.0, max=1800.0),
    ),
    "segmentation": (
        _positive("rotating_rpm", 2.0, "RPM", "Surface speed above which the string starts "
                  "to count as rotating."),
        _positive("rotating_stop_rpm", 1.0, "RPM", "Surface speed below which rotation ends "
                  "(hysteresis: noise at standstill does not chatter; a creep stays whole)."),
        _positive("min_rotation_s", 2.0, "s", "Rotation shorter than this is speed noise and "
                  "not listed as a segment at all."),
        Key("dip_max_s", float, 10.0, "s", "Longest dip of the surface speed below "
            "rotating_stop_rpm that stays inside a rotation while the string stays loaded "
            "(a soft-torque or slow top-drive controller lets the top drive almost stop "
            "between slips while the string is wound up). 0: every stop ends the rotation. "
            "The batch fit joins its rotating runs by the same rule.",
            min=0.0, max=600.0),
        Key("dip_torque_fraction", float, 0.5, "", "A speed dip is loaded while the torque "
            "holds at least this fraction of the rotating torque level (a running mean over "
            "10 s of rotation); a released string ends the rotation at once.", min=0.0,
            max=1.0, min_exclusive=True),
        _positive("min_segment_s", 30.0, "s", "Shortest rotating segment that is estimated; "
                  "shorter ones are kept as 'skipped'."),
        _positive("on_bottom_m", 0.5, "m", "Bit within this distance of hole depth counts "
                  "as on bottom."),
        _positive("wob_on_bottom_N", 10e3, "N", "WOB above which the bit counts as on bottom "
                  "when depths are missing, and while turning within a stand (30 m) of the "
                  "hole's bottom whatever the depth channels say."),
        _positive("max_gap_s", 10.0, "s", "A gap in the time base longer than this splits a "
                  "segment."),
        _positive("kind_dwell_s", 20.0, "s", "A change between on and off bottom must last "
                  "this long to split a rotating segment (shorter excursions are absorbed)."),
        _positive("slips_hookload_N", None, "N", "Hook load below which the string is in the "
                  "slips (above the empty-hook weight, below the lightest string weight); "
                  "without it no in-slips detection."),
        _positive("trip_speed_m_s", 0.1, "m/s", "Bit (or block) speed above which a "
                  "non-rotating string off bottom counts as tripping."),
        _positive("ream_speed_m_s", 0.05, "m/s", "Axial pipe speed (bit depth rate, from the "
                  "bit depth or the block position) above which a string turning off bottom "
                  "is reaming (running in) or back-reaming (pulling out): the wall friction "
                  "then splits between axial and tangential: those segments' μ_k comes from "
                  "the moving load case, their μ_s and bit speed are withheld "
                  "(docs/segmentation.md). At 0.05 m/s and 40 RPM a 7-in tool joint loses "
                  "under 1 % of its tangential friction.", max=100.0),
        _positive("max_rop_m_h", 300.0, "m/h", "Fastest drilling: a bit going below the "
                  "known hole depth faster than this is running into existing hole (off "
                  "bottom). A huge value switches the speed gate off.", max=1e7),
        _positive("pumps_on_Pa", 1.0e6, "Pa", "Standpipe pressure above which the pumps count "
                  "as on (used when neither flow in nor pump rate is recorded)."),
        _positive("pumps_on_spm", 10.0, "1/min", "Pump rate above which the pumps count as "
                  "on (used when flow in is not recorded)."),
        _positive("pumps_on_m3_s", 0.002, "m³/s", "Flow in above which the pumps count as on."),
        Key("start_bit_depth_m", float, None, "m", "Bit depth at the first sample when bit "
            "depth is reckoned from block position (without it segment depths are unknown). "
            "Needs slips_hookload_N: the string moves with the block only off the slips.",
            min=0.0),
    ),
    "hookload": (
        Key("tolerance", float, 0.05, "", "Relative tolerance of the hook-load check "
            "(docs/theory.md §2.1): the string weight the log measures (rotating off-bottom "
            "hook load − block weight in the slips) may differ from the configured string's "
            "buoyed weight by this share before the friction factors are withheld. μ scales "
            "as 1/string weight, so this is the μ error the check lets through: 5 % = the "
            "μ_k tolerance (a larger one admits hook-load sensor error, ±2–5 %, at the cost "
            "of μ_k that far off).", min=0.02, max=0.5),
        Key("block_weight_N", float, None, "N", "Weight of the travelling block, hook and "
            "top drive on the hook (rig specification; 0 for a hook load zeroed on the empty "
            "block), used when the log holds no in-slips plateau to weigh it: without either "
            "the log cannot weigh the string, the hook-load verdict is 'unverified' and the "
            "friction factors are withheld (docs/theory.md §2.1).", min=0.0, max=5e6),
        Key("calibrate_string_weight", bool, False, "", "When the hook load contradicts the "
            "configured string, scale the string's buoyed weight to the measured one (a "
            "first pass over the log; needs the block weight, from the slips or "
            "block_weight_N; scale within "
            "0.5–2) instead of withholding the friction factors. The result says so "
            "(flag string_weight_calibrated, summary.json hookload)."),
    ),
    "friction_log": (
        _positive("window_m", 30.0, "m", "Depth window of the static friction log of a "
                  "depth-indexed log (docs/ingestion.md): the rows of each window give one "
                  "back-calculated friction factor per load case (default: one stand).",
                  max=1000.0),
        Key("min_rows", int, 3, "", "Fewest rotating rows a window needs for a friction "
            "factor (fewer: the window is listed as skipped).", min=1),
        Key("bit_mu", float, 0.0, "", "Bit friction coefficient μ_bit of the bit torque "
            "assumed on bottom, T_bit = μ_bit·WOB·D_bit/3. 0 (default): no bit torque is "
            "separated, so the on-bottom factor is apparent friction including the bit torque.",
            min=0.0, max=2.0),
        _positive("bit_diameter_m", 0.2159, "m", "Bit diameter D_bit of the assumed bit "
                  "torque (used when bit_mu > 0).", max=1.5),
    ),
    "wits0": (
        Key("units", str, "metric", "", "Units the rig recorder sends over WITS level 0 "
            "(`drillfric live wits0://HOST:PORT`, docs/live.md): 'metric' (m, m/h, KDN = "
            "10 kN, kN·m, kPa) or 'field' (ft, ft/h, klbf, kft·lbf, psi). Any item's code or "
            'unit: [channels], e.g. hookload = { column = "0114", unit = "kN" }.',
            choices=("metric", "field")),
        Key("utc_offset_h", float, None, "h", "UTC offset of the rig clock that the date and "
            "time items give (local time = UTC + offset): times are then recorded in UTC. "
            "Default: recorded as the rig clock gives them, without a zone.",
            min=-14.0, max=14.0),
        Key("handshake_s", float, 20.0, "s", "Seconds between the handshake frames sent to "
            "the recorder (Pason-style recorders stop sending without one at least every "
            "30 s; others ignore them); 0: none.", min=0.0, max=3600.0),
        Key("reconnect_max_s", float, 5.0, "s", "Longest wait between two attempts to "
            "reconnect after the stream dropped (the wait doubles from 0.2 s up to this).",
            min=0.2, max=600.0),
    ),
    "simulate": (
        Key("bit_depth_m", float, None, "m", "Bit depth of a single-stand simulation "
            "(default: the survey's last station).", min=0.0, min_exclusive=True),
        Key("rpm", float, 60.0, "RPM", "Constant surface speed set-point after the ramp "
            "(at most 600 RPM: no top drive turns faster).", min=0.0, max=600.0),
        Key("mu_s", float, 0.6, "", "True static friction factor.", min=0.0, max=2.0),
        Key("mu_k", float, 0.3, "", "True kinetic friction factor.", min=0.0, max=2.0),
        _positive("kp_Nms_rad", 38e3, "N·m·s/rad", "PI speed controller proportional gain."),
        Key("ki_Nm_rad", float, 100e3, "N·m/rad", "PI speed controller integral gain.",
            min=0.0),
        Key("rpm_noise", float, 0.0, "RPM", "Gaussian noise on the recorded surface speed.",
            min=0.0, max=100.0),
        Key("torque_noise_Nm", float, 0.0, "N·m", "Gaussian noise on the recorded torque.",
            min=0.0),
        Key("cells", int, 2500, "", "Cells of the simulated (true) string: finer than the "
            "estimator's model.cells, since creep torque is not grid-converged on coarse "
            "grids (docs/theory.md §6.4: dx ≤ MD/1000).", min=20, max=200000),
        _positive("duration_s", 120.0, "s", "Simulated time of a single-stand run; with a "
                  "scenario, the rotating time of stands that do not give their own."),
        Key("rate_hz", float, 100.0, "Hz", "Recording rate of the simulated surface data "
            "(0.01–10000 Hz: from 100-s recorder blocks to ten times the fastest rig logs).",
            min=0.01, max=1e4),
        _positive("ramp_s", 10.0, "s", "Time of the set-point ramp from rest to `rpm`."),
        Key("seed", int, 0, "", "Seed of the measurement noise.", min=0),
        Key("scenario", str, None, "", "Scenario file of several stands (TOML, relative to the "
            "config; see docs/simulator.md). Without it: one stand."),
        Key("rpm_resolution", float, 0.0, "RPM", "Quantisation step of the recorded surface "
            "speed (0: none).", min=0.0, max=100.0),
        Key("torque_resolution_Nm", float, 0.0, "N·m", "Quantisation step of the recorded "
            "torque (0: none).", min=0.0),
        Key("hookload_noise_N", float, 0.0, "N", "Gaussian noise on the recorded hook load.",
            min=0.0),
        Key("wob_N", float, 0.0, "N", "Weight on bit of a single-stand run (> 0: bit on "
            "bottom with the Coulomb bit-torque model).", min=0.0),
        Key("bit_mu", float, 0.3, "", "Bit friction coefficient μ_bit of the bit-torque model "
            "T_bit = μ_bit·WOB·D_bit/3.", min=0.0, max=2.0),
        _positive("bit_diameter_m", 0.2159, "m", "Bit diameter D_bit (bit-torque model and "
                  "hole size).", max=1.5),
        Key("bit_weakening_ratio", float, 1.0, "", "Rate-weakening bit (docs/simulator.md, "
            "Bit): ratio r of the break-away to the high-speed bit torque, "
            "T_bit(ω) = T_k·(1 + (r − 1)·exp(−|ω|/ω_b)) with T_k = μ_bit·WOB·D_bit/3; 1 is "
            "the Coulomb bit.", min=1.0, max=10.0),
        _positive("bit_weakening_rpm", 10.0, "RPM", "Decay speed ω_b of the rate-weakening "
                  "bit torque (used when bit_weakening_ratio > 1).", max=1000.0),
        Key("flow_m3_s", float, 0.0, "m³/s", "Flow in of every stand that gives none (pumps on "
            "throughout the stand, off in connections; recorded as flow_in_m3_s when > 0).",
            min=0.0, max=0.2),
        Key("motor_rev_per_litre", float, None, "rev/L", "Mud motor of the simulated BHA: "
            "its no-load speed per unit of flow, k (docs/simulator.md, Mud motor); the truth "
            "bit_rpm is then the BHA's (bha_rpm) plus the motor's. The run's own [bha] table "
            "declares it or not. Default: no motor.", min=0.0, min_exclusive=True, max=10.0),
        Key("motor_stall_torque_Nm", float, None, "N·m", "Stall torque of the simulated "
            "motor: its speed falls linearly with the bit torque, ω_m = 2π·k·Q·(1 − "
            "τ_bit/τ_stall) (docs/theory.md eq. 2.4b). Default: no drop.", min=0.0,
            min_exclusive=True),
        Key("off_bottom_m", float, 5.0, "m", "Distance of the bit above hole bottom in "
            "off-bottom stands (recorded hole depth = bit depth + this).", min=0.0),
        Key("friction_law", str, "step", "", "Friction law of the truth (docs/theory.md §3.2): "
            "'step' (μ_s below ω_c, μ_k above, the paper's) or 'stribeck' (μ falls "
            "continuously from μ_s at rest to μ_k at speed).", choices=("step", "stribeck")),
        _positive("stribeck_speed_rad_s", 1.0, "rad/s", "Stribeck decay speed v_s: "
                  "μ = μ_k + (μ_s − μ_k)·exp(−(|ω|/v_s)^δ) (friction_law = 'stribeck')."),
        Key("stribeck_exponent", float, 1.0, "", "Stribeck exponent δ (1: exponential, 2: "
            "Gaussian decay).", min=1.0, max=2.0),
        Key("mu_s_cased", float, None, "", "True static friction factor above "
            "model.casing_shoe_md_m (with mu_k_cased; mu_s, mu_k are then the open-hole "
            "truth).", min=0.0, max=2.0),
        Key("mu_k_cased", float, None, "", "True kinetic friction factor above "
            "model.casing_shoe_md_m (with mu_s_cased).", min=0.0, max=2.0),
        Key("torque_lag_s", float, 0.0, "s", "Lag of the recorded surface torque behind the "
            "speed (positive: logged late, as by a second acquisition device; "
            "docs/bit_speed.md, Channel skew). The configuration written beside the data "
            "states it as [channels] surface_torque lag_s.", min=-10.0, max=10.0),
    ),
}

#: Keys of each ``[[string.sections]]`` entry (top-down; the first fills up to the bit).
SECTION_KEYS: tuple[Key, ...] = (
    Key("name", str, "", "", "Section name (e.g. '5 7/8in DP')."),
    _positive("od_m", None, "m", "Body outside diameter.", max=1.0),
    Key("id_m", float, None, "m", "Inside diameter (< od_m).", min=0.0, max=1.0),
    _positive("length_m", None, "m", "Length; omit for the first (top) section, whose length "
              "follows from the bit depth."),
    _positive("tool_joint_od_m", None, "m", "Tool-joint OD; contact radius = "
              "tool_joint_od_m/2 (default od_m/2).", max=1.0),
    _positive("linear_mass_kg_m", None, "kg/m", "Adjusted mass per metre including tool "
              "joints (default: steel area × steel density)."),
    _positive("shear_modulus_Pa", 79.3e9, "Pa", "Shear modulus G."),
    _positive("steel_density_kg_m3", 7850.0, "kg/m³", "Steel density ρ."),
)

#: Documented default drill string, used (and reported as assumed) when a config has none:
#: the A&S 2018 drill pipe, 5in heavy-weight and 8in collars (docs/reference_cases.md).
#: How the assumed list names the built-in default string (its start: the sections follow).
STRING_ASSUMED = "drill string: typical"
DEFAULT_SECTIONS: tuple[dict, ...] = (
    {"name": "5 7/8in DP (assumed)", "od_m": 0.146529, "id_m": 0.123024,
     "tool_joint_od_m": 0.1778, "linear_mass_kg_m": 41.41},
    {"name": "5in HWDP (assumed)", "od_m": 0.127, "id_m": 0.0762, "length_m": 110.0,
     "tool_joint_od_m": 0.1651, "linear_mass_kg_m": 74.5},
    {"name": "8in collars (assumed)", "od_m": 0.2032, "id_m": 0.0714, "length_m": 120.0},
)
#: The note when ``[rig] top_drive_inertia_kg_m2`` is not given (the schema's default, A&S
#: 2018); only the observer of a time log uses the inertia, so a depth log does not list it.
TOP_DRIVE_INERTIA_ASSUMED = "top-drive inertia 2900 kg·m² (A&S 2018)"

#: Channel keys accepted in ``[channels]`` (canonical names without the unit suffix).
CHANNEL_KEYS = ("time", "measured_depth", "surface_rpm", "surface_torque", "hookload",
                "bit_depth", "hole_depth", "wob", "block_position", "bit_rpm", "standpipe_pressure",
                "flow_in", "flow_out", "pump_rate", "surface_torque_min", "surface_torque_max",
                "surface_rpm_min", "surface_rpm_max", "hookload_min", "hookload_max")
_CHANNEL_FIELDS = {"column": (str, int), "unit": str, "mnemonics": list, "scale": (int, float),
                   "lag_s": (int, float, str)}
#: Channels a ``lag_s`` may be given for: the pair whose relative timing the observer reads
#: (docs/theory.md §5.3); the estimation corrects the torque by lag(torque) − lag(speed).
LAG_CHANNELS = ("surface_torque", "surface_rpm")
#: Largest ``lag_s`` magnitude accepted [s]: a recorder's skew is seconds, not minutes.
CHANNEL_LAG_MAX_S = 10.0
#: Magnitudes a channel's `scale` may have: a sign flip or a factor no unit conversion
#: gives (1e300 had been taken, overflowing every value: issue 30, eighth attack).
CHANNEL_SCALE = (1e-6, 1e6)


def default(dotted: str) -> Any:
    """The schema's default of ``"table.key"`` (for library functions whose parameters
    mirror a configuration key: one source for every default).

    Examples
    --------
    >>> default("rig.top_drive_inertia_kg_m2")
    2900.0
    """
    table, key = dotted.split(".")
    return next(k.default for k in SCHEMA[table] if k.name == key)


def _table_type(table: str, keys: tuple[Key, ...]) -> type:
    """A frozen dataclass for one table of :data:`SCHEMA`: one field per key, with its
    default, and its unit and help in the field metadata (typed access, ``cfg.model.cells``)."""
    return make_dataclass(
        f"{table.title()}Settings",
        [(k.name, k.type if not isinstance(k.type, tuple) else Any,
          field(default=k.default if not isinstance(k.default, list) else None,
                metadata={"unit": k.unit, "help": k.help}))
         for k in keys], frozen=True)


#: The typed table of each :data:`SCHEMA` table, generated from it.
TABLE_TYPES: dict[str, type] = {t: _table_type(t, keys) for t, keys in SCHEMA.items()}


@dataclass(frozen=True)
class Config:
    """Effective well configuration (defaults < file < command line).

    Every table of :data:`SCHEMA` is an attribute with one field per key, generated from the
    schema: ``cfg.model.k_t_per_s``, ``cfg.rig.top_drive_inertia_kg_m2`` (absent keys hold
    their schema default, possibly ``None``).

    Attributes
    ----------
    values : dict
        ``{table: {key: value}}`` for every table of :data:`SCHEMA` (absent keys hold their
        default, possibly ``None``).
    sections : tuple of dict
        ``[[string.sections]]`` entries, top-down, each with every :data:`SECTION_KEYS` key.
    channels : dict
        ``{channel_key: {"column": ..., "unit": ..., "mnemonics": [...]}}`` overrides.
    source : Path or None
        The file the configuration came from.
    assumed : tuple of str
        Human-readable notes of what was assumed by default (shown loudly in outputs).
    """

    values: dict
    sections: tuple
    channels: dict
    source: Path | None = None
    assumed: tuple = field(default_factory=tuple)

    def __post_init__(self):
        for table, kind in TABLE_TYPES.items():
            object.__setattr__(self, table, kind(**self.values[table]))

    def get(self, dotted: str) -> Any:
        """The value of ``"table.key"`` (for keys chosen at run time, e.g. by the CLI)."""
        table, key = dotted.split(".")
        return getattr(getattr(self, table), key)

    @property
    def omega_c_rad_s(self) -> float:
        """Static/kinetic switching speed ω_c [rad/s] (from either model key; default 1)."""
        from drillfric.units import RPM_TO_RAD_S

        if self.model.omega_c_rad_s is not None:
            return self.model.omega_c_rad_s
        if self.model.omega_c_rpm is not None:
            return self.model.omega_c_rpm * RPM_TO_RAD_S
        return 1.0

    @property
    def tortuosity_rad_m(self) -> float:
        """Nominal tortuosity of the path assumed without a survey [rad/m] (0: vertical)."""
        return math.radians(self.survey.tortuosity_deg_30m) / 30.0

    def assumed_with(self, survey) -> list[str]:
        """What a command assumed: :attr:`assumed` and, when ``survey`` is None, the hole
        (:attr:`no_survey_note`)."""
        return list(self.assumed) + ([self.no_survey_note] if survey is None else [])

    @property
    def no_survey_note(self) -> str:
        """What is assumed about the hole when there is no survey (for the assumed list)."""
        tortuosity = self.survey.tortuosity_deg_30m
        if tortuosity == 0:
            return "vertical well: no survey found"
        text = f"{tortuosity:.1f}" if round(tortuosity, 1) == tortuosity else f"{tortuosity:g}"
        return (f"a vertical well with a nominal tortuosity of {text}°/30 m, no survey found "
                "(survey.tortuosity_deg_30m; friction factors scale about as 1/tortuosity)")

    @property
    def inner_mud_density_kg_m3(self) -> float:
        """Mud density inside the string [kg/m³] (defaults to the annulus density)."""
        inner = self.fluid.inner_mud_density_kg_m3
        return self.fluid.mud_density_kg_m3 if inner is None else inner

    def to_dict(self) -> dict:
        """Plain-data effective configuration, as written into summary.json."""
        out = {t: dict(v) for t, v in self.values.items()}
        out["string"] = {"sections": [dict(s) for s in self.sections]}
        out["channels"] = {k: dict(v) for k, v in self.channels.items()}
        return out


def _table(raw: dict, table: str, keys: tuple[Key, ...], file: str | None,
           prefix: str) -> dict:
    if not isinstance(raw, dict):
        raise ConfigError(f"'{prefix}' must be a table", file=file, fix=f"write [{prefix}]")
    known = {k.name: k for k in keys}
    for name in raw:
        if name not in known:
            close = ", ".join(sorted(known))
            raise ConfigError(f"unknown key '{prefix}.{name}'", file=file,
                              fix=f"remove it or use one of: {close}")
    return {k.name: (k.validate(raw[k.name], f"{prefix}.{k.name}", file) if k.name in raw
                     else k.default) for k in keys}


def _sections(raw: Any, file: str | None) -> tuple[dict, ...]:
    if not isinstance(raw, list) or not raw:
        raise ConfigError("'string.sections' must be a non-empty array of tables", file=file,
                          fix="write one [[string.sections]] table per section, top-down")
    out = []
    for i, entry in enumerate(raw, start=1):
        sec = _table(entry, "string.sections", SECTION_KEYS, file, f"string.sections[{i}]")
        where = f"string.sections[{i}]"
        if sec["od_m"] is None or sec["id_m"] is None:
            raise ConfigError(f"{where} needs od_m and id_m", file=file)
        if sec["id_m"] >= sec["od_m"]:
            raise ConfigError(f"{where}: id_m ({sec['id_m']}) must be smaller than od_m "
                              f"({sec['od_m']})", file=file, fix="check the pipe dimensions")
        joint = sec["tool_joint_od_m"]
        if joint is not None and joint < sec["od_m"]:
            raise ConfigError(f"{where}: tool_joint_od_m ({joint}) is smaller than od_m "
                              f"({sec['od_m']}): a tool joint is at least as wide as its "
                              "pipe, and its radius is where the string touches the hole",
                              file=file, fix="give the joint's outside diameter, or leave "
                                             "tool_joint_od_m out (the pipe's OD is used)")
        if i > 1 and sec["length_m"] is None:
            raise ConfigError(f"{where} needs length_m (only the top section may omit it)",
                              file=file)
        out.append(sec)
    return tuple(out)


def _channels(raw: Any, file: str | None) -> dict:
    if not isinstance(raw, dict):
        raise ConfigError("'channels' must be a table", file=file)
    out = {}
    for name, spec in raw.items():
        if name not in CHANNEL_KEYS:
            raise ConfigError(f"unknown channel '{name}' in [channels]", file=file,
                              fix=f"use one of: {', '.join(CHANNEL_KEYS)}")
        if isinstance(spec, (str, int)) and not isinstance(spec, bool):
            spec = {"column": spec}
        if not isinstance(spec, dict):
            raise ConfigError(f"channels.{name} must be a table like "
                              f'{{ column = "SRPM", unit = "rpm" }}', file=file)
        for key, value in spec.items():
            if key not in _CHANNEL_FIELDS:
                raise ConfigError(f"unknown key 'channels.{name}.{key}'", file=file,
                                  fix="use column, unit, scale, lag_s or mnemonics")
            if not isinstance(value, _CHANNEL_FIELDS[key]) or isinstance(value, bool):
                raise ConfigError(f"channels.{name}.{key} has the wrong type", file=file,
                                  fix='e.g. { column = "SRPM", unit = "rpm", scale = -1 }')
            if key == "scale" and not (_is_number(value) and
                                       CHANNEL_SCALE[0] <= abs(value) <= CHANNEL_SCALE[1]):
                raise ConfigError(f"channels.{name}.scale must be a number of magnitude "
                                  f"{CHANNEL_SCALE[0]:g}–{CHANNEL_SCALE[1]:g}", file=file,
                                  fix="e.g. scale = -1 for a log of opposite sign; a unit "
                                      "goes in `unit`")
        out[name] = dict(spec)
        if "lag_s" in spec:
            out[name]["lag_s"] = _channel_lag(name, spec["lag_s"], file)
    return out


def _channel_lag(name: str, value: Any, file: str | None) -> float:
    """``channels.NAME.lag_s`` in seconds (a number, or text with a time unit: "800 ms").

    Raises
    ------
    ConfigError
        A lag on a channel other than :data:`LAG_CHANNELS`, a unit of another quantity, or a
        magnitude above :data:`CHANNEL_LAG_MAX_S`.
    """
    where = f"channels.{name}.lag_s"
    if name not in LAG_CHANNELS:
        raise ConfigError(f"{where}: a lag is read for {' and '.join(LAG_CHANNELS)} only",
                          file=file, fix="give the torque's lag relative to the speed, e.g. "
                                         "surface_torque = { column = \"STOR\", lag_s = 0.8 }")
    if isinstance(value, str):
        from drillfric.units import quantity_value
        value = quantity_value(value, "second", what=f"key '{where}'", file=file)
    if not (_is_number(value) and abs(value) <= CHANNEL_LAG_MAX_S):
        raise ConfigError(f"{where} must be a time of magnitude ≤ {CHANNEL_LAG_MAX_S:g} s",
                          file=file, fix="positive: the channel is logged late, e.g. 0.8")
    return float(value)


def torque_lag_s(channels: dict) -> float | None:
    """The configured lag of the torque behind the speed [s]: ``lag_s`` of surface_torque
    minus that of surface_rpm (None: neither given, the lag is identified from the data).

    Examples
    --------
    >>> torque_lag_s({"surface_torque": {"lag_s": 0.8}}), torque_lag_s({})
    (0.8, None)
    """
    lags = [channels.get(key, {}).get("lag_s") for key in LAG_CHANNELS]
    if all(lag is None for lag in lags):
        return None
    return (lags[0] or 0.0) - (lags[1] or 0.0)


def _check_hole(sections: tuple[dict, ...], bit_diameter_m: float | None,
                file: str | None) -> None:
    """ConfigError when a section's widest part (tool joint, else pipe) does not pass
    through the hole the bit drilled (``well.bit_diameter_m``)."""
    if bit_diameter_m is None:
        return
    for i, sec in enumerate(sections, start=1):
        widest = max(sec["od_m"], sec["tool_joint_od_m"] or 0.0)
        if widest >= bit_diameter_m:
            raise ConfigError(f"string.sections[{i}] is {widest} m wide (od_m / "
                              f"tool_joint_od_m), not less than well.bit_diameter_m "
                              f"({bit_diameter_m}): it does not fit in the hole",
                              file=file, fix="check the section's diameters (in metres) and "
                                             "the bit diameter")


def _is_number(value) -> bool:
    """A finite TOML number (NaN and inf are typos in a well configuration)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(
        value)


def _check_observer_lists(observer: dict, file: str | None) -> None:
    """List-valued keys: ``starts`` = [[μ_s, μ_k], ...] with 0 ≤ μ_k ≤ μ_s ≤ ``mu_max``,
    ``poles_per_s`` = two positive numbers."""
    starts = observer["starts"]
    for i, pair in enumerate(starts, start=1):
        ok = (isinstance(pair, list) and len(pair) == 2 and all(map(_is_number, pair))
              and 0 <= pair[1] <= pair[0])
        if not ok:
            raise ConfigError(f"observer.starts[{i}] = {pair!r} must be [μ_s, μ_k] numbers with "
                              "0 ≤ μ_k ≤ μ_s", file=file,
                              fix="e.g. starts = [[0.3, 0.2], [0.6, 0.4]]")
    if not starts:
        raise ConfigError("observer.starts is empty", file=file,
                          fix="e.g. starts = [[0.3, 0.2], [0.6, 0.4]]")
    highest = max(pair[0] for pair in starts)
    if highest > observer["mu_max"]:
        raise ConfigError(f"observer.mu_max = {observer['mu_max']:g} is below the observer "
                          f"starts (observer.starts: μ_s up to {highest:g}), which must lie "
                          "within the clamp",
                          file=file, fix="raise observer.mu_max or give observer.starts "
                                         "within it")
    poles = observer["poles_per_s"]
    if len(poles) != 2 or not all(_is_number(p) and p > 0 for p in poles):
        raise ConfigError(f"observer.poles_per_s = {poles!r} must be two positive numbers "
                          "[z, p] in 1/s", file=file, fix="e.g. poles_per_s = [1.0, 1.5]")


def _check_friction(model: dict, file: str | None) -> None:
    """The friction keys of [model] that go together (docs/theory.md §3.2)."""
    if model["friction_cased"] is not None and model["friction_ratio_cased"] is not None:
        raise ConfigError("give model.friction_cased or model.friction_ratio_cased, not both",
                          file=file, fix="the cased friction is known either absolutely or "
                                         "as a ratio of the open hole's")
    static, kinetic = model["friction_cased_static"], model["friction_cased"]
    if static is not None and (kinetic is None or static < kinetic):
        raise ConfigError("model.friction_cased_static needs friction_cased and must not be "
                          "below it", file=file, fix="e.g. friction_cased = 0.2, "
                                                     "friction_cased_static = 0.3")
    if model["friction_law"] == "stribeck" and model["stribeck_speed_rad_s"] is None:
        raise ConfigError("model.friction_law = 'stribeck' needs model.stribeck_speed_rad_s",
                          file=file, fix="e.g. stribeck_speed_rad_s = 0.5")


def read_toml(path: str | Path) -> dict:
    """Read a TOML file, turning syntax errors into one-line ConfigErrors."""
    path = Path(path)
    require_file(path, "config file", error=ConfigError)
    try:
        with path.open("rb") as fh:
            text = fh.read().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError("not a text file", file=path,
                          fix="save the configuration as UTF-8 TOML text") from exc
    return parse_toml(text, path)


def parse_toml(text: str, where) -> dict:
    """The tables of TOML ``text``; a syntax error, or arrays and tables nested deeper than
    Python's parser recurses (``x = [[[[…]]]]`` a hundred thousand deep), is one
    ConfigError naming ``where``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"not valid TOML ({exc})", file=where,
                          fix="check the line it names (quotes around text, = between key "
                              "and value)") from exc
    except RecursionError:
        raise ConfigError("not a configuration drillfric reads (arrays or tables nested too "
                          "deep to parse)", file=where,
                          fix="write the configuration's tables and values as "
                              "docs/configuration.md shows them") from None


def config_from_dict(raw: dict, *, file: str | Path | None = None,
                     overrides: dict[str, Any] | None = None) -> Config:
    """Validate a raw configuration mapping and apply ``overrides``.

    Parameters
    ----------
    raw : dict
        Parsed TOML (may be empty).
    file : str or Path, optional
        Where ``raw`` came from, for messages.
    overrides : dict, optional
        ``{"table.key": value}`` from the command line (``None`` values are ignored).
    """
    fname = None if file is None else str(file)
    allowed = set(SCHEMA) | {"string", "channels"}
    for table in raw:
        if table not in allowed:
            raise ConfigError(f"unknown table or key '{table}'", file=fname,
                              fix=f"use one of: {', '.join(sorted(allowed))}")
    values = {t: _table(raw.get(t, {}), t, keys, fname, t) for t, keys in SCHEMA.items()}
    string = raw.get("string", {})
    if not isinstance(string, dict) or set(string) - {"sections"}:
        raise ConfigError("[string] only holds [[string.sections]]", file=fname)
    assumed = []
    if "sections" in string:
        sections = _sections(string["sections"], fname)
    else:
        sections = _sections([dict(s) for s in DEFAULT_SECTIONS], "built-in default")
        assumed.append(f"{STRING_ASSUMED} 5 7/8in DP + 110 m 5in HWDP + 120 m 8in collars")
    channels = _channels(raw.get("channels", {}), fname)
    given = []
    for dotted, value in (overrides or {}).items():
        if value is None:
            continue
        table, key = dotted.split(".")
        spec = {k.name: k for k in SCHEMA[table]}[key]
        values[table][key] = spec.validate(value, dotted, "command line")
        given.append(dotted)
    try:
        _check_together(values, sections, fname)
    except ConfigError as exc:
        said = [d for d in given if d in exc.problem]
        if not said:
            raise
        # a value the command line gave is at fault, not the file (an invalid --starts was
        # blamed on the TOML: issue 30, tenth attack)
        options = ", ".join(f"{OPTION_NAMES[d]} ({d})" if d in OPTION_NAMES else d
                            for d in said)
        rest = f"; the other keys from {fname}" if fname else ""
        raise ConfigError(f"{exc.problem}{rest}", file=f"command line {options}",
                          fix=f"correct {options.split(' (')[0] if len(said) == 1 else 'them'}"
                              + (f" (or {exc.fix})" if exc.fix else "")) from exc
    if raw.get("rig", {}).get("top_drive_inertia_kg_m2") is None:
        assumed.append(TOP_DRIVE_INERTIA_ASSUMED)
    if "fluid" not in raw:
        assumed.append("mud density 1200 kg/m³")
    return Config(values=values, sections=sections, channels=channels,
                  source=None if file is None else Path(file), assumed=tuple(assumed))


#: The command-line options that set configuration keys (for messages about their values).
OPTION_NAMES = {"observer.starts": "--starts", "well.units": "--units"}


def _check_together(values: dict, sections, fname: str | None) -> None:
    """The checks of keys that must go together, after the command line's overrides."""
    _check_observer_lists(values["observer"], fname)
    if values["segmentation"]["rotating_stop_rpm"] > values["segmentation"]["rotating_rpm"]:
        raise ConfigError("segmentation.rotating_stop_rpm must not exceed rotating_rpm "
                          "(rotation starts above rotating_rpm and ends below the stop speed)",
                          file=fname, fix="e.g. rotating_rpm = 2.0, rotating_stop_rpm = 1.0")
    _check_friction(values["model"], fname)
    _check_hole(sections, values["well"]["bit_diameter_m"], fname)
    if values["model"]["omega_c_rad_s"] is not None and values["model"]["omega_c_rpm"] is not None:
        raise ConfigError("give either model.omega_c_rad_s or model.omega_c_rpm, not both",
                          file=fname)


def load_config(path: str | Path | None = None, *,
                overrides: dict[str, Any] | None = None) -> Config:
    """Load a well configuration TOML (or only defaults when ``path`` is None)."""
    raw = {} if path is None else read_toml(path)
    return config_from_dict(raw, file=path, overrides=overrides)


def schema_markdown() -> str:
    """Render the configuration reference (docs/configuration.md) from :data:`SCHEMA`."""
    lines = ["# Configuration reference", "",
             "Generated from `drillfric.config.SCHEMA` (`python -m drillfric.config > "
             "docs/configuration.md`); a test fails when this file and the schema differ.",
             "", "A well configuration is a TOML file (`NAME.toml` beside the data, "
             "`well.toml` in a well directory, or `--config FILE`). Precedence: command line "
             "> config file > defaults. Unknown keys are an error naming the key and file.", "",
             "**Units.** A key's unit is in its name and in the *unit* column. Any key with a "
             "unit also takes a number with another unit, written as text: "
             '`mud_density_kg_m3 = "10.5 ppg"`, `od_m = "5 1/2 in"`, '
             '`linear_mass_kg_m = "19.5 lb/ft"`, `wob_N = "40 klbf"`, `bit_depth_m = '
             '"8200 ft"`. It is converted exactly to the key\'s unit (the float nearest the '
             "exact value: a field-unit configuration gives bit-for-bit the results of its SI "
             "twin); a unit of another quantity is an error naming the key, the file and the "
             "quantity expected. Spellings: docs/ingestion.md (*Units in configurations and "
             "options*).", ""]

    def rows(keys):
        out = ["| key | type | unit | default | range | description |",
               "|---|---|---|---|---|---|"]
        for k in keys:
            types = k.type if isinstance(k.type, tuple) else (k.type,)
            tname = "/".join(t.__name__ for t in types)
            rng = k.range_text() or (" / ".join(k.choices) if k.choices else "")
            default = "—" if k.default is None else f"`{k.default}`"
            out.append(f"| `{k.name}` | {tname} | {k.unit} | {default} | {rng} | {k.help} |")
        return out

    for table, keys in SCHEMA.items():
        lines += [f"## [{table}]", ""] + rows(keys) + [""]
    lines += ["## [[string.sections]]", "",
              "Top-down array of tables; the first section's length follows from the bit "
              "depth. Without any, the default string below is assumed (and reported).", ""]
    lines += rows(SECTION_KEYS) + ["", "Default string:", ""]
    lines += [f"- {s['name']}: OD {s['od_m']} m, ID {s['id_m']} m"
              + (f", {s['length_m']} m" if "length_m" in s else ", fills to the bit")
              for s in DEFAULT_SECTIONS]
    lines += ["", "## [channels]", "",
              "Maps canonical channels to columns of the data file and their units, e.g. "
              '`surface_torque = { column = "STOR", unit = "kN.m" }`. A column may be a name or '
              "a 0-based index (headerless files). `mnemonics = [...]` adds names to recognise; "
              "`scale` multiplies the values after the unit conversion (`scale = -1` for a "
              f"log of opposite sign; magnitude {CHANNEL_SCALE[0]:g}–{CHANNEL_SCALE[1]:g}). "
              "`lag_s` (surface_torque and surface_rpm only; seconds, or text such as "
              '`"800 ms"`; magnitude ≤ 10 s) states how late the channel is logged: positive, '
              "the torque lags the speed, e.g. "
              '`surface_torque = { column = "STOR", lag_s = 0.8 }`. The estimation shifts the '
              "torque by lag(surface_torque) − lag(surface_rpm) and does not identify the lag "
              "from the data (docs/bit_speed.md, *Channel skew*).",
              "", "Channel keys: " + ", ".join(f"`{c}`" for c in CHANNEL_KEYS), ""]
    return "\n".join(lines)


if __name__ == "__main__":
    print(schema_markdown(), end="")
