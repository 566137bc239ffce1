"""The real-mocap results as a page (docs/results/realmocap.md) and a figure of real and generated frames."""
from collections import defaultdict

import matplotlib
import numpy as np

from rlanimate_addon.core import skeleton
from trainer.motion.realmocap_takes import HOLDOUT_STYLES, TAKE_GROUPS, TEST_TAKES, VALIDATION_TAKES, parse_name
from trainer.reporting.baselines_report import METHOD_LABELS
from trainer.reporting.paired import gap_cell, paired_gap
from trainer.reporting.tables import page, paragraphs, section, table

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def frames_figure(env, rows, path, times=(0.15, 0.35, 0.5, 0.65, 0.85)):
    """Front views of real (grey) and generated (red) frames side by side; one row per (title, real
    (F, 15, 3), generated (F, 15, 3)) in `rows`, one column per fraction of the clip in `times`."""
    names = env.bone_names
    links = [(names.index(b.name), names.index(b.parent)) for b in skeleton.BONES
             if b.parent and b.name in names and b.parent in names
             and not any(part in b.name for part in ("Eye", "Thumb", "Middle", "Ring", "Pinky", "Toe", "_End"))]
    figure, axes = plt.subplots(len(rows), len(times), figsize=(2.2 * len(times), 2.6 * len(rows)), squeeze=False)
    for r, (title, real, generated) in enumerate(rows):
        heads = {"real": env.evaluate(real).bone_heads, "generated": env.evaluate(generated).bone_heads}
        for c, fraction in enumerate(times):
            ax = axes[r, c]
            frame = int(round(fraction * (len(real) - 1)))
            for key, offset, colour in (("real", -0.45, "0.35"), ("generated", 0.45, "tab:red")):
                # The character faces -Y: seen from the front, its left (+X) is on the viewer's right.
                points = heads[key][frame]
                for child, parent in links:
                    ax.plot([points[child, 0] + offset, points[parent, 0] + offset],
                            [points[child, 2], points[parent, 2]], color=colour, lw=1.5)
            ax.set_xlim(-1.4, 1.4)
            ax.set_ylim(0.0, 2.4)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(f"t = {fraction:.2f} N", fontsize=8)
            if c == 0:
                ax.set_ylabel(title, fontsize=7)
    figure.suptitle("Real capture on the sample rig (grey, left) and RLAnimate (red, right), front view", fontsize=9)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


#: The per-style table's measures: (key of style_summaries' entries, decimals).
STYLE_METRICS = (("score", 1), ("aligned_score", 1), ("swing_ratio", 2), ("frequency_ratio", 2),
                 ("elevation_last_error", 1), ("accepted", 0))


def style_summaries(result):
    """{style: {takes, score, aligned_score (means), swing_ratio, frequency_ratio, elevation_last_error
    (medians; degrees), accepted (waves core.behaviour_metrics accepts)}} of one method's scoring on a wave
    set, its takes grouped by the style in their file names."""
    by_style = defaultdict(list)
    for clip in result["clips"]:
        by_style[parse_name(clip["name"])["style"]].append(clip)
    summaries = {}
    for style, clips in sorted(by_style.items()):
        def values(key, clips=clips):
            return np.array([clip[key] for clip in clips], dtype=np.float64)
        summaries[style] = {"takes": len(clips), "score": float(values("score").mean()),
                            "aligned_score": float(values("aligned_score").mean()),
                            "swing_ratio": _median_of_defined(values("swing_ratio")),
                            "frequency_ratio": _median_of_defined(values("frequency_ratio")),
                            "elevation_last_error": float(np.median(values("elevation_last_error"))),
                            "accepted": int(values("wave_accepted").sum())}
    return summaries


def _median_of_defined(values):
    """The median of the values that are not NaN (a ratio to a reference without swing); NaN when none is."""
    defined = values[~np.isnan(values)]
    return float(np.median(defined)) if len(defined) else float("nan")


def metric_cells(summary, metrics):
    """The `summary`'s values of `metrics` ((key, decimals), ...) as table cells."""
    return [f"{summary[key]:.{digits}f}" for key, digits in metrics]


def mean_and_sd(values, digits):
    """'mean ± sd' of per-seed values (sd with ddof 1), at least one decimal."""
    values = np.asarray(values, dtype=np.float64)
    digits = max(digits, 1)
    return f"{values.mean():.{digits}f} ± {values.std(ddof=1):.{digits}f}"


def over_seeds(values, digits):
    """'mean ± sd' of several seeds' values (mean_and_sd), or one seed's value at `digits` decimals."""
    return mean_and_sd(values, digits) if len(values) > 1 else f"{values[0]:.{digits}f}"


def per_style_rows(set_label, methods, seeds):
    """Rows of the per-style table for one test set: per style, RLAnimate (each seed's agent, from `seeds`
    {seed: seed_summary}: their mean ± sd when there are several), then the other methods of `methods`
    ({method: scoring result with per-clip 'clips'})."""
    per_seed = [summary["by_style"] for summary in seeds.values()]
    others = {method: style_summaries(result) for method, result in methods.items() if method != "rlanimate"}
    rows = []
    for style in sorted(per_seed[0]):
        takes = per_seed[0][style]["takes"]
        if len(per_seed) > 1:
            cells = [mean_and_sd([entry[style][key] for entry in per_seed], digits) for key, digits in STYLE_METRICS]
            label = f"RLAnimate, mean ± sd of {len(per_seed)} seeds"
        else:
            cells = metric_cells(per_seed[0][style], STYLE_METRICS)
            label = f"RLAnimate, seed {next(iter(seeds))}"
        rows.append([set_label, style, label, takes, *cells[:-1], f"{cells[-1]} / {takes}"])
        for method, summaries in others.items():
            cells = metric_cells(summaries[style], STYLE_METRICS)
            rows.append([set_label, style, METHOD_LABELS[method], takes, *cells[:-1], f"{cells[-1]} / {takes}"])
    return rows


#: An experiment's result sets as the tables show them: the test takes and the goodbye waves, each answered
#: with the take's label and length and again naming its tempo (trainer.experiments.realmocap.REQUESTS).
SET_LABELS = {"test": "test", "test_tempo": "test, tempo asked", "bye": "bye", "bye_tempo": "bye, tempo asked"}
SEED_SETS = (("wave", "test", "takes 009-010"), ("wave", "test_tempo", "takes 009-010, tempo asked"),
             ("wave", "bye", "goodbye waves"), ("wave", "bye_tempo", "goodbye waves, tempo asked"),
             ("holdout", "test", "unseen styles"), ("holdout", "test_tempo", "unseen styles, tempo asked"))
#: The seeds table's columns and their decimals (the mean ± sd row keeps at least one).
SEED_METRICS = (("score", 1), ("aligned_score", 1), ("swing_ratio_median", 2), ("frequency_ratio_median", 2),
                ("elevation_last_error_median", 1), ("accepted", 0))


def seed_summary(result):
    """One method's (for RLAnimate, one seed's agent's) scoring on one wave set: clips, score, smoothness,
    label error, DTW score, median swing and frequency ratios and last-frame elevation error, the waves
    `core.behaviour_metrics` accepts, and the same per style (style_summaries)."""
    wave = result["by_behaviour"]["wave"]
    return {"clips": len(result["clips"]),
            **{key: result[key] for key in ("score", "smoothness", "label_error") if key in result},
            "aligned_score": wave["aligned_score"], "swing_ratio_median": wave["swing_ratio_median"],
            "frequency_ratio_median": wave["frequency_ratio_median"],
            "elevation_last_error_median": wave["elevation_last_error_median"],
            "accepted": int(round(wave["accepted_share"] * len(result["clips"]))),
            "by_style": style_summaries(result), "take_scores": take_scores(result)}


#: The per-take measures the side-by-side table pairs: (key of a clip's row, what the table calls it).
PAIRED_MEASURES = (("score", "score"), ("aligned_score", "DTW"))


def take_scores(result):
    """{measure: [per take, in the set's order]} of a scoring result's clips, for PAIRED_MEASURES."""
    return {key: [clip[key] for clip in result["clips"]] for key, _ in PAIRED_MEASURES}


def seed_rows(results):
    """Rows of the seeds table: per wave test set of SEED_SETS the results hold, RLAnimate's agent of each seed,
    their mean ± sd, and nearest-clip retrieval (which has no seed)."""
    rows = []
    for name, set_name, label in SEED_SETS:
        if set_name not in results[name]:
            continue
        per_seed = results[name][f"{set_name}_seeds"]
        rows += [[label, f"RLAnimate, seed {seed}", *metric_cells(summary, SEED_METRICS)]
                 for seed, summary in per_seed.items()]
        if len(per_seed) > 1:
            spread = [f"**{mean_and_sd([summary[key] for summary in per_seed.values()], digits)}**"
                      for key, digits in SEED_METRICS]
            rows.append([label, f"RLAnimate, mean ± sd of {len(per_seed)}", *spread])
        rows.append(
            [
                label,
                METHOD_LABELS["nearest_clip"],
                *metric_cells(seed_summary(results[name][set_name]["nearest_clip"]), SEED_METRICS),
            ]
        )
    return rows


#: The test sets the side-by-side table asks both ways: (experiment, set, label).
BOTH_REQUEST_SETS = (("wave", "test", "takes 009-010"), ("holdout", "test", "unseen styles"),
                     ("wave", "bye", "goodbye waves"))
#: The two requests, by the suffix of their result keys (trainer.experiments.realmocap.REQUESTS).
REQUEST_LABELS = {"": "the paper's (label only)", "_tempo": "tempo asked"}


def seed_take_means(methods, seeds):
    """({measure: per-take mean over the seeds' agents}, seeds used) of RLAnimate on one set: seed_summary's
    take_scores of each seed that has them, else the first seed's full result alone."""
    kept = [summary["take_scores"] for summary in seeds.values() if "take_scores" in summary]
    kept = kept or [take_scores(methods["rlanimate"])]
    return {key: np.mean([scores[key] for scores in kept], axis=0) for key, _ in PAIRED_MEASURES}, len(kept)


def request_cells(methods, seeds):
    """Cells of one set and request: RLAnimate's score / DTW (mean ± sd over seeds), retrieval's, and the paired
    gaps (RLAnimate's per-take mean over seeds - retrieval's, 95% interval over the takes)."""
    ours, used = seed_take_means(methods, seeds)
    theirs = take_scores(methods["nearest_clip"])
    per_seed = [[summary[key] for key, _ in PAIRED_MEASURES] for summary in seeds.values()]
    agent = " / ".join(over_seeds(values, 1) for values in zip(*per_seed, strict=True))
    retrieval = " / ".join(f"{np.mean(theirs[key]):.1f}" for key, _ in PAIRED_MEASURES)
    return [agent, retrieval, *(gap_cell(paired_gap(ours[key], theirs[key])) for key, _ in PAIRED_MEASURES),
            f"{used}"]


def both_request_rows(results):
    """Rows of the side-by-side table: each set of BOTH_REQUEST_SETS, asked the paper's way and with the tempo."""
    rows = []
    for name, set_name, label in BOTH_REQUEST_SETS:
        for suffix, request in REQUEST_LABELS.items():
            key = set_name + suffix
            if key in results.get(name, {}):
                rows.append([label, request, *request_cells(results[name][key], results[name][f"{key}_seeds"])])
    return rows


def fallback_notes(results):
    """One line per set whose tempo-asked requests fell back to the label for some takes, naming them and why."""
    notes = []
    for name, set_name, label in BOTH_REQUEST_SETS:
        fallbacks = results.get(name, {}).get(f"{set_name}_tempo", {}).get("rlanimate", {}).get("tempo_fallbacks")
        if fallbacks:
            notes.append(f"- {label}, tempo asked: {len(fallbacks)} take(s) asked with the label alone: " +
                         "; ".join(f"{take} ({why})" for take, why in fallbacks.items()) + ".")
    return notes


#: What the side-by-side table shows.
_BOTH_REQUESTS = (
    "Each test take asked the paper's way (its auto-label and length) and again naming its tempo (the Hz at "
    "which its hand swings, as a user types it in the panel's Tempo). Score / DTW score: RLAnimate's mean ± "
    "sd over the seeds' agents, and nearest-clip retrieval's from the same training takes. Gap: RLAnimate's "
    "per-take score (mean over the seeds paired: those whose per-take scores the results keep, the first "
    "seed's alone in pages scored before they were kept) minus retrieval's on the same take, mean and 95% "
    "interval over the takes.")


def both_requests_section(results):
    """Lines of the page's first section: each test set asked both ways, side by side (both_request_rows)."""
    notes = fallback_notes(results)
    return [*section("Both requests, side by side", _BOTH_REQUESTS),
            *table(["test set", "request", "RLAnimate score / DTW", "retrieval score / DTW",
                    "paired score gap (95%)", "paired DTW gap (95%)", "seeds paired"], both_request_rows(results)),
            *([*notes, ""] if notes else [])]


def cpu_list(entry):
    """An experiment's training CPU seconds per seed, as 'N s (seed S), ...'."""
    return ", ".join(f"{seconds:.0f} s (seed {seed})" for seed, seconds in entry["train_cpu_seconds"].items())


#: What the report says a group of takes is for, beside its name, by its takes.
TAKE_GROUP_ROLES = {VALIDATION_TAKES: " (validation)", TEST_TAKES: " (test)"}


def _take_group_cell(entry):
    """'0.73, 1.29 Hz (16)' for a tempo_table `by_takes` entry; '' for none."""
    if entry is None:
        return ""
    tempo = "no swing" if entry["spectrum_hz"] is None else f"{entry['spectrum_hz']:.2f} Hz"
    return f"{entry['exaggeration']:.2f}, {tempo} ({entry['takes']})"


#: The test sets of the label-reach table: (experiment, what the report calls its test).
REACH_SETS = (("wave", "takes 009-010"), ("holdout", "unseen styles"))


def reach_widths(results):
    """The label neighbourhoods' half-widths (as keyed) of the label-reach table, narrowest first."""
    return list(next(iter(results["label_reach"]["wave"]["styles"].values()))["near"])


def reach_rows(results):
    """Rows of the label-reach table (trainer/evaluation/label_reach.py), per test set and style; the styles of the
    training waves are named for the widest neighbourhood."""
    widest = reach_widths(results)[-1]
    rows = []
    for name, set_label in REACH_SETS:
        reach = results["label_reach"][name]
        for style, entry in reach["styles"].items():
            near, rules = entry["near"], entry["rules"]
            rows.append([set_label, style, str(entry["takes"]), "{:.2f}-{:.2f}".format(*entry["labels"]),
                         f"{entry['tempo_hz']:.2f}",
                         ", ".join(f"{cell['in_reach']}/{cell['waves']}" for cell in near.values()),
                         ", ".join(near[widest]["styles"]) or "none",
                         ", ".join(near[widest]["in_reach_styles"]) or "none",
                         f"{rules['lowest']:.2f}-{rules['highest']:.2f} ({rules['in_band']}/{reach['rules']})"])
    return rows


#: The paragraph under the auto-labels table: the two readings of a style's tempo.
_TEMPO_READINGS = (
    "Tempo, median over the style's takes, read two ways: the peak of the hand's side-to-side "
    "spectrum (how the trainer reads a training wave's rhythm, and the Tempo a request names), and "
    "the strokes between turning points at least 8% of the shoulder width apart "
    "(`core.behaviour_metrics.wave_measures`, whose frequency ratio the tables below report); stroke: "
    "their median length. Where the strokes are small (a tremble) the two disagree, and the frequency "
    "ratio judges a wave by the second.")
_TAKE_GROUPS_NOTE = (
    "Each cell: the mean exaggeration, the median tempo as the trainer reads it (spectrum), and the "
    "takes. Takes 007-008 validate what takes 009-010 test (trainer/experiments/realmocap_length.py). Where a "
    "style's tempo moves from one group of takes to another while its label barely does, a rhythm drawn "
    "from the label cannot follow it, and validation on takes 007-008 cannot show what it costs on takes "
    "009-010.")
_REQUESTS = (
    "Every method answers each test take's request twice: with the take's auto-label and length (the "
    "paper's request; *test*, *bye*), and with the same naming the take's own tempo as well (*tempo "
    "asked*: the Hz at which its hand swings side to side, read as the trainer reads a training wave's; "
    "the panel's Tempo). One exaggeration cannot say a tempo: masculine and normal waves share one label "
    "and swing at different rates. Asked a tempo, RLAnimate swings at it; retrieval ranks the training "
    "waves by exaggeration and log tempo, each in units of its sd; procedural IK swings at it.")
_BEHAVIOUR = (
    "Each generated wave against the real take for the same request (docs/METRICS.md): the score after "
    "time alignment (DTW), the medians of the swing and frequency ratios (issue 10 asks 0.75-1.33x "
    "and 0.8-1.2x) and of the full cycles while the hand is up, and the waves that "
    "`core.behaviour_metrics` accepts.")
_PER_STYLE = (
    "Over a style's test takes (takes 009-010: two takes x two arms; unseen styles: takes 001-010 x two "
    "arms): mean score and DTW score; median swing and frequency ratios (issue 26 asks 0.75-1.33 and "
    "0.8-1.25 in every style) and last-frame arm elevation error (degrees; asked: at most 4); waves "
    "accepted. RLAnimate: mean ± sd over the seeds' agents when there are several.")
#: The columns of the per-style and seeds tables after the test set (and style, method and takes).
_STYLE_COLUMNS = ["score", "DTW score", "swing ratio", "frequency ratio", "last-frame elevation error (deg)",
                  "accepted"]


def realmocap_markdown(results):
    """docs/results/realmocap.md from the results run_experiments returns."""
    return page(_introduction(results), both_requests_section(results), _labels_section(results),
                _reach_section(results), _score_sections(results), _seeds_section(results),
                section("Guide clips as pointing"), _guide_section(results["guide"]))


def _introduction(results):
    """The page's title, what the capture and the agents are, and the command."""
    seeds = results["seeds"]
    return ["# Learning from real motion capture", "", *paragraphs(
        f"Bandai Namco Research motion dataset (CC BY-NC 4.0, Kobayashi et al. 2023), brought onto the "
        f"sample rig with a synthesised relaxed hand and labelled from the motion (docs/REALMOCAP.md). "
        f"Preset `{results['preset']}`, {results['epochs']} epochs, seeds "
        f"{', '.join(str(seed) for seed in seeds)} (the tables but the last are seed {seeds[0]}'s). "
        f"Regenerate: `{results['command']}`.",
        *([f"**One seed only (seed {seeds[0]}): no spread over seeds is given, and one seed's agent can sit a few "
           "points either side of the mean.**"] if len(seeds) == 1 else []))]


def _labels_section(results):
    """The waves' auto-labels and tempos per style, and per group of takes."""
    tempos, styles = results["tempos"], results["labels"]["wave"]
    label_rows = [[style, f"{row['exaggeration']:.2f} ± {row['exaggeration_sd']:.2f}", f"{row['elevation_deg']:.0f}",
                   f"{row['stroke_arm_lengths']:.2f}", f"{row['arm_correct']}/{row['clips']}",
                   f"{tempos[style]['spectrum_hz']:.2f}", f"{tempos[style]['strokes_hz']:.2f}",
                   f"{tempos[style]['stroke_cm']:.1f}"] for style, row in styles.items()]
    take_group_rows = [[style, *(_take_group_cell(tempos[style]["by_takes"].get(group)) for group in TAKE_GROUPS)]
                       for style in styles]
    return [*section("Auto-labels per style (one-arm waves: takes 001-010 and 021-036)"),
            *table(["style", "exaggeration (mean ± sd)", "elevation (deg)", "stroke (arm lengths)", "arm detected",
                    "tempo, spectrum (Hz)", "tempo, strokes (Hz)", "stroke (cm)"], label_rows),
            *paragraphs(_TEMPO_READINGS),
            *section("Label and tempo by group of takes", level=3),
            *table(["style", *(f"takes {group}" + TAKE_GROUP_ROLES.get(takes, "")
                               for group, takes in TAKE_GROUPS.items())], take_group_rows),
            *paragraphs(_TAKE_GROUPS_NOTE)]


def _reach_section(results):
    """What tempo the label can reach (reach_rows), and the goodbye waves' labels."""
    widths, reach = reach_widths(results), results["label_reach"]
    in_every_style = ", ".join(f"{label} {reach[name]['in_band_in_every_style']} of {reach[name]['rules']}"
                               for name, label in REACH_SETS)
    return [*section("What tempo the label can reach", level=3),
            *table(["test set", "style", "takes", "labels", "tempo (Hz)",
                    f"training waves within ±{', ±'.join(widths)} of its labels: within 0.8-1.25x of its tempo / all",
                    f"styles within ±{widths[-1]}", f"styles within ±{widths[-1]} and 0.8-1.25x",
                    "rate played / its own, median over its takes: lowest-highest over the rules "
                    "(rules within 0.8-1.25x)"], reach_rows(results)),
            *paragraphs(
                "From the training waves and the test takes alone, no agent (trainer/evaluation/label_reach.py): "
                "a rhythm taken from the training waves near a request's exaggeration, as RLAnimate's and "
                "retrieval's are, can only swing at a rate those waves swing at. The rules are the rhythm model's "
                "exaggeration kernels of sd 0.01-1, with the mean rhythm or the typical tempo (tempo kernels log "
                "1.05, 1.25, 2), from both arms' waves or the request's arm's. Rules whose median lies within "
                f"0.8-1.25x in every style: {in_every_style}. A diagnosis of the tests, nothing chosen from it.",
                "Goodbye waves: " + ", ".join(f"{style} {row['exaggeration']:.2f}"
                                              for style, row in results["labels"]["bye"].items()))]


def _experiments(results):
    """The experiments of the score tables: (key of the results, its label from its training clips and styles)."""
    return (("wave", f"wave agent, takes 001-008 and 021-036 ({results['wave']['train_clips']} clips)"),
            ("holdout", f"wave agent, 5 styles ({results['holdout']['train_clips']} clips; unseen: "
                        f"{', '.join(HOLDOUT_STYLES)})"))


def _score_rows(label, entry):
    """Rows of the score table and of the behaviour table of one experiment (its results `entry`)."""
    scores, behaviours = [], []
    for set_name, set_label in SET_LABELS.items():
        for method, result in entry.get(set_name, {}).items():
            clips, wave = len(result["clips"]), result["by_behaviour"]["wave"]
            shown = [label, f"{set_label} ({clips})", METHOD_LABELS[method]]
            scores.append([*shown, f"{result['score']:.2f}", f"{result['smoothness']:.2f}",
                           f"{result['label_error']:.3f}"])
            behaviours.append([*shown, f"{wave['aligned_score']:.2f}", f"{wave['swing_ratio_median']:.2f}",
                               f"{wave['frequency_ratio_median']:.2f}", f"{wave['cycles_median']:.0f}",
                               f"{round(wave['accepted_share'] * clips)}/{clips}"])
    seen = entry["seen"]
    scores.append([label, f"seen ({seen['clips']} training clips)", "RLAnimate", f"{seen['score']:.2f}",
                   f"{seen['smoothness']:.2f}", ""])
    return scores, behaviours


def _score_sections(results):
    """Score and smoothness, behaviour and behaviour per style, per experiment, test set and method."""
    score_rows, behaviour_rows, style_rows = [], [], []
    for name, label in _experiments(results):
        entry = results[name]
        scores, behaviours = _score_rows(label, entry)
        score_rows += scores
        behaviour_rows += behaviours
        for set_name in ("test", "test_tempo"):
            shown = next(shown for experiment, key, shown in SEED_SETS if (experiment, key) == (name, set_name))
            style_rows += per_style_rows(shown, entry[set_name], entry[f"{set_name}_seeds"])
    return [*section("Score and smoothness", _REQUESTS, "Label error: mean |exaggeration auto-labelled from the "
                     "generated wave - requested exaggeration|."),
            *table(["experiment", "test set", "method", "score", "smoothness", "label error"], score_rows),
            *section("Behaviour", _BEHAVIOUR),
            *table(["experiment", "test set", "method", "DTW score", "swing ratio", "frequency ratio", "cycles",
                    "accepted"], behaviour_rows),
            *section("Per style", _PER_STYLE, level=3),
            *table(["test set", "style", "method", "takes", *_STYLE_COLUMNS], style_rows)]


def _seeds_section(results):
    """Each seed's agent on the wave sets, the training and scoring times, and a pointer to the ablation."""
    return [*section("Seeds", "RLAnimate trained with each seed, on the same sets: mean score and DTW score, median "
                     "swing and frequency ratios and last-frame elevation error, waves accepted (the mean ± sd row is "
                     "over the seeds).", level=3),
            *table(["test set", "method", *_STYLE_COLUMNS], seed_rows(results)),
            *paragraphs(
                f"CPU time (one torch thread): training, per seed's agent ({results['wave']['episodes']} "
                f"episodes), {cpu_list(results['wave'])} for the wave agent and {cpu_list(results['holdout'])} for "
                f"the hold-out agent; scoring every method, request and seed, "
                f"{results['evaluation_cpu_seconds']:.0f} s.",
                "The wave's rhythm at play time (its phase, the kernel, seeded draws), varied on seed 0's agents "
                "without retraining: [realmocap_ablation.md](realmocap_ablation.md).")]


def _guide_section(guide):
    """The pointing agent's forearm angle on the guide clips per method (or why it was not run), and the figure."""
    figure = "![real and generated frames](realmocap_frames.png)"
    if "skipped" in guide:
        return paragraphs(f"Not run: {guide['skipped']}", figure)
    rows = [[METHOD_LABELS[method], f"{entry['mean_forearm_angle_deg']:.1f}",
             f"{entry['median_forearm_angle_deg']:.1f}"] for method, entry in guide.items() if isinstance(entry, dict)]
    return [*paragraphs(f"Pointing agent `{guide['point_agent']}`, given the direction in which the actor held the arm "
                        "(rest shoulder to the index base at the hold). Angle between the generated and the real "
                        "forearm (elbow to wrist), each at its own hold:"),
            *table(["method", "mean (deg)", "median (deg)"], rows), *paragraphs(figure)]
