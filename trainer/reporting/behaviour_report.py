"""docs/results/behaviour.{json,md}: the behaviour metrics of RLAnimate and the baselines, methods as rows."""
import json
import math
from pathlib import Path

from trainer.files import atomic_write_text
from trainer.reporting.baselines_report import METHOD_LABELS
from trainer.reporting.tables import page, paragraphs, section, table

WAVE_COLUMNS = ("score", "score, class length", "score, DTW", "smoothness", "swing ratio: median (range)",
                "frequency ratio", "full cycles: min / median", "hand height ratio", "waves accepted",
                "elevation error first / last (deg, median; max)")
POINT_COLUMNS = ("score", "score, class length", "score, DTW", "smoothness", "pointing angle (deg): median / max",
                 "hold ratio", "elevation error first / last (deg, median; max)")
GUIDE_COLUMNS = ("score", "score, class length", "score, DTW", "smoothness", "heading error (deg): median / max",
                 "palm from up (deg): median / max", "reach (arm lengths)", "hold ratio", "guides accepted",
                 "elevation error first / last (deg, median; max)")
RAISE_COLUMNS = ("score", "score, class length", "score, DTW", "smoothness", "height error (arm lengths): median / max",
                 "forearm from vertical (deg, max)", "hold (s, min)", "strokes (max)", "raises accepted",
                 "elevation error first / last (deg, median; max)")


def _f(value, digits=2):
    return "n/a" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.{digits}f}"


def _elevation(entry):
    return (f"{_f(entry['elevation_first_error_median'], 1)} / {_f(entry['elevation_last_error_median'], 1)}; "
            f"{_f(entry['elevation_first_error_max'], 1)} / {_f(entry['elevation_last_error_max'], 1)}")


def _scores(entry):
    return [_f(entry[k]) for k in ("score", "score_class_length", "aligned_score", "smoothness")]


def behaviour_words(behaviour, entry):
    """One line of a clip set's behaviour measures (an evaluation.behaviour.summarise entry)."""
    elevation = (
        f"elevation error <= {_f(max(entry['elevation_first_error_max'], entry['elevation_last_error_max']), 1)} deg"
    )
    if behaviour == "wave":
        return (f"swing {_f(entry['swing_ratio_median'])}x, frequency {_f(entry['frequency_ratio_median'])}x, "
                f"at least {entry['cycles_min']:.0f} cycles, {entry['accepted_share'] * entry['requests']:.0f} of "
                f"{entry['requests']} waves accepted; {elevation}")
    if behaviour == "guide":
        return (f"heading {_f(entry['heading_error_median'], 1)} deg median, palm {_f(entry['palm_up_median'], 0)} deg "
                f"from up, {_accepted(entry)} guides accepted; {elevation}")
    if behaviour == "raise_hand":
        return (f"height error {_f(entry['height_error_median'])} arm lengths median, {_accepted(entry)} raises "
                f"accepted; {elevation}")
    if "hand_height_error_median" in entry:
        return (f"intensity: hand height error {_f(entry['hand_height_error_median'])} arm lengths median "
                f"({_f(entry['hand_height_error_max'])} max), free arm rise {_f(entry['free_arm_rise_max'])} max; "
                f"{elevation}")
    if "aim_error_median" in entry:
        return (f"target: aim error {_f(entry['aim_error_median'], 1)} deg median ({_f(entry['aim_error_max'], 1)} "
                f"max), free arm rise {_f(entry['free_arm_rise_max'])} max; {elevation}")
    if "pointing_angle_median" in entry:
        return (f"own aim {_f(entry['pointing_angle_median'], 1)} deg median, {_f(entry['pointing_angle_max'], 1)} "
                f"max; {elevation}")
    return elevation


def clip_words(row):
    """One line of a scored clip's measures (a scoring.clip_row), named for what its behaviour or kind measures."""
    if "wave_accepted" in row:
        return (f"swing {_f(row['swing_ratio'])}x, frequency {_f(row['frequency_ratio'])}x, "
                f"{'accepted' if row['wave_accepted'] else 'not accepted'}")
    if "guide_accepted" in row:
        return f"heading {_f(row['heading_error'], 1)} deg, {'accepted' if row['guide_accepted'] else 'not accepted'}"
    if "raise_accepted" in row:
        return (f"height error {_f(row['height_error'])} arm lengths, "
                f"{'accepted' if row['raise_accepted'] else 'not accepted'}")
    if "pointing_angle" in row:
        return f"own aim {_f(row['pointing_angle'], 1)} deg"
    if "hand_height_error" in row:
        return (f"intensity: hand height error {_f(row['hand_height_error'])} arm lengths, free arm rise "
                f"{_f(row['free_arm_rise'])}")
    if "aim_error" in row:
        return f"target: aim error {_f(row['aim_error'], 1)} deg, free arm rise {_f(row['free_arm_rise'])}"
    return f"elevation error last frame {_f(row['elevation_last_error'], 1)} deg"


def _accepted(entry):
    return f"{entry['accepted_share'] * entry['requests']:.0f} of {entry['requests']}"


def guide_row(entry):
    return _scores(entry) + [f"{_f(entry['heading_error_median'], 1)} / {_f(entry['heading_error_max'], 1)}",
                             f"{_f(entry['palm_up_median'], 0)} / {_f(entry['palm_up_max'], 0)}",
                             _f(entry["reach_median"]), _f(entry["hold_ratio_median"]), _accepted(entry),
                             _elevation(entry)]


def raise_row(entry):
    return _scores(entry) + [f"{_f(entry['height_error_median'], 3)} / {_f(entry['height_error_max'], 3)}",
                             _f(entry["forearm_from_vertical_max"], 1), _f(entry["hold_s_min"]),
                             f"{entry['strokes_max']:.0f}", _accepted(entry), _elevation(entry)]


def wave_row(entry):
    return _scores(entry) + [
        f"{_f(entry['swing_ratio_median'])} ({_f(entry['swing_ratio_min'])}-{_f(entry['swing_ratio_max'])})",
        _f(entry["frequency_ratio_median"]),
        f"{entry['cycles_min']:.0f} / {entry['cycles_median']:.1f}",
        _f(entry["hand_height_ratio_median"]),
        f"{entry['accepted_share'] * entry['requests']:.0f} of {entry['requests']}",
        _elevation(entry),
    ]


def point_row(entry):
    return _scores(entry) + [f"{_f(entry['pointing_angle_median'], 1)} / {_f(entry['pointing_angle_max'], 1)}",
                             _f(entry["hold_ratio_median"]), _elevation(entry)]


#: The intro's definitions paragraph.
_DEFINITIONS = (
    "Definitions: docs/METRICS.md (\"Behaviour metrics\"). Ratios are generated / reference per request. "
    "Scores are means over the requests; the behaviour measures are medians, with the extremes where the "
    "issue sets a bound (swing 0.75-1.33x, frequency within 20%, at least 2 full cycles, pointing at most "
    "3 degrees median and 8 at worst, elevation within 10 degrees).")
#: The method tables of the held-out clips, each shown where the report has its set: (title, key of
#: report["sets"], columns, row of an entry, paragraphs before the table, paragraphs after it).
_METHOD_TABLES = (
    ("Waves", "wave", WAVE_COLUMNS, wave_row, (), ()),
    ("Points, each method's own aim (no aim correction)", "point", POINT_COLUMNS, point_row, (), ()),
    ("Points with exact aim (aim correction applied)", "point_exact_aim", POINT_COLUMNS, point_row, (),
     ("Aim correction turns the arm towards the target from the start of the stroke (core/aim.py's pointing phase), "
      "so the finger arrives before the reference's does: the frame-by-frame scores fall, the time-aligned (DTW) "
      "score does not.",)),
    ('"This way" (guide)', "guide", GUIDE_COLUMNS, guide_row,
     ('docs/METRICS.md ("Guide and raise hand"); accepted: heading error at most 20 degrees, palm at most 65 degrees '
      "from up, reach at least 0.5 arm lengths, held 0.4 s or more.",), ()),
    ("Raise hand", "raise_hand", RAISE_COLUMNS, raise_row,
     ('docs/METRICS.md ("Guide and raise hand"); accepted: held 0.5 s or more above the shoulder, forearm within 30 '
      "degrees of vertical, at most 3 strokes, height within 0.1 arm lengths of the reference's.",), ()))


def _method_tables(sets):
    """A section per set of _METHOD_TABLES in `sets` ({key: {method: summarise entry}}): the methods as rows."""
    lines = []
    for title, key, columns, row, before, after in _METHOD_TABLES:
        if key in sets:
            methods = sets[key]
            lines += [*section(f"{title}, held-out clips ({next(iter(methods.values()))['requests']})", *before),
                      *table(("method",) + columns, [[METHOD_LABELS.get(m, m)] + row(e) for m, e in methods.items()]),
                      *paragraphs(*after)]
    return lines


def behaviour_markdown(report):
    """The markdown page of a behaviour report (see trainer/scripts/behaviour.py for its keys)."""
    agent = report["agent"]
    figures = [f"- `{f}`: {text}" for f, text in report.get("figures", {}).items()]
    return page(["# Behaviour: do the gestures wave, point, raise and lower the arm?", ""],
                paragraphs(report["description"], _DEFINITIONS), _method_tables(report["sets"]),
                section("RLAnimate on its own"), _random_targets(agent), _exaggeration_sweep(agent),
                _guide_targets(agent), _raise_sweep(agent), _seeds(agent),
                [*section("Figures"), *figures, ""] if figures else [])


def _random_targets(agent):
    """Each arm's own and exact aim at random unseen targets."""
    return [*section(f"Pointing at {agent['targets_per_arm']} random unseen targets per arm",
                     "Targets drawn uniformly over the library's ranges (azimuth -60 to 95 degrees, elevation -40 to "
                     "55, 1.5-4 m from the shoulder), at the class-average length.", level=3),
            *table(("arm", "own aim: median / max (deg)", "exact aim: median / max (deg)", "hold (s, median)"),
                   [[arm, f"{_f(s['own']['median_angle'], 1)} / {_f(s['own']['max_angle'], 1)}",
                     f"{_f(s['exact']['median_angle'], 2)} / {_f(s['exact']['max_angle'], 2)}",
                     _f(s["own"]["median_hold_s"])] for arm, s in agent["random_targets"].items()])]


def _exaggeration_sweep(agent):
    """Each arm's wave swing per exaggeration, its cycles, and whether the swing rises."""
    sweeps = agent["exaggeration_sweep"]
    exaggerations = next(iter(sweeps.values()))["exaggerations"]
    return [*section("Exaggeration sweep (class-average length)", level=3),
            *table(("arm",) + tuple(f"swing at {e:g} (cm)" for e in exaggerations) + ("cycles", "rising"),
                   [[arm] + [_f(100 * v, 1) for v in s["swing"]]
                    + [" ".join(str(c) for c in s["cycles"]), "yes" if s["swing_rising"] else "no"]
                    for arm, s in sweeps.items()])]


def _guide_targets(agent):
    """Each arm's guides to random unseen targets; none for an agent without guide."""
    if "guide_targets" not in agent:
        return []
    return [*section(f"\"This way\" to {agent['targets_per_arm']} random unseen targets per arm",
                     "Targets drawn uniformly over the library's guiding ranges (azimuth -30 to 95 degrees, elevation "
                     "-35 to 12, 1.5-5 m from the shoulder), at the class-average length.", level=3),
            *table(("arm", "accepted", "heading error: median / max (deg)", "palm from up: median / max (deg)",
                    "reach (arm lengths)", "hold (s, median)"),
                   [[arm, f"{100 * s['accepted_share']:.0f}%",
                     f"{_f(s['heading_error_median'], 1)} / {_f(s['heading_error_max'], 1)}",
                     f"{_f(s['palm_up_median'], 0)} / {_f(s['palm_up_max'], 0)}", _f(s["reach_median"]),
                     _f(s["hold_s_median"])] for arm, s in agent["guide_targets"].items()])]


def _raise_sweep(agent):
    """Each arm's raised wrist height per exaggeration; none for an agent without raise hand."""
    if "raise_sweep" not in agent:
        return []
    sweeps = agent["raise_sweep"]
    exaggerations = next(iter(sweeps.values()))["exaggerations"]
    return [*section("Raise-hand exaggeration sweep (class-average length)", level=3),
            *table(("arm",) + tuple(f"wrist above shoulder at {e:g} (cm)" for e in exaggerations)
                   + ("Spearman", "rising"),
                   [[arm] + [_f(100 * v, 1) for v in s["height"]]
                    + [_f(s["spearman"]), "yes" if s["height_rising"] else "no"] for arm, s in sweeps.items()])]


def _seeds(agent):
    """The variation seeds' waves and points, and how far apart the seeds' answers lie."""
    seeded, variation = agent["seeded"], agent["variation"]
    spread = {name: f"median {_f(100 * variation[name]['median'], 1)} cm (range {_f(100 * variation[name]['min'], 1)}-"
                    f"{_f(100 * variation[name]['max'], 1)})" for name in ("wave", "point")}
    return [*section("Seeds", "Each variation seed's answers to the held-out requests (the panel's Seed; seed 0 is "
                     "the deterministic answer in the tables above), measured as above:", "Waves:", level=3),
            *table(("seed",) + WAVE_COLUMNS, [[seed] + wave_row(e["wave"]) for seed, e in seeded.items()]),
            *paragraphs("Points, own aim:"),
            *table(("seed",) + POINT_COLUMNS, [[seed] + point_row(e["point"]) for seed, e in seeded.items()]),
            *paragraphs(f"Mean distance between the seeds' joint positions (all joints, all frames, each request at "
                        f"its own length): waves {spread['wave']}, points {spread['point']}. The deterministic "
                        f"answer repeats exactly on {variation['deterministic']} of {variation['requests']} requests.")]


def _plain(value):
    """JSON-ready: NaN becomes null (JSON has no NaN)."""
    if isinstance(value, float) and math.isnan(value):
        return None
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def write_behaviour(results_dir, report):
    """Write behaviour.json (the report, per-request rows included) and behaviour.md into results_dir."""
    results_dir = Path(results_dir)
    atomic_write_text(results_dir / "behaviour.json", json.dumps(_plain(report), indent=1) + "\n")
    atomic_write_text(results_dir / "behaviour.md", behaviour_markdown(report))
