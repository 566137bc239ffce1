"""Evaluation as in the paper's Section 4: score and smoothness of deterministic rollouts, with the
behaviour metrics beside them.

For each clip the agent is rolled out deterministically on the clip's objectives (a baseline answers
the same request), the motions are played through the FK environment (all clips in one batch), and the
descriptions are compared with the FK of the clip's own motion by the one scorer, `score_descriptions`:
`metrics.score(generated, reference)`, `metrics.smoothness(generated)`, the time-aligned score
(`behaviour_metrics.aligned_score`) and the behaviour measures (`behaviour_metrics.compare`: wave, point,
raise and lower). A clip set's scores are the means over its clips, its behaviour measures the medians
and extremes of `evaluation.behaviour.summarise`.
"""
from functools import partial

import numpy as np

from rlanimate_addon.core import behaviour_metrics, behaviours, metrics, spaces
from trainer.agent.algorithm import clip_objective, rollout_actions
from trainer.evaluation.behaviour import clip_target, summarise

SEEN_CLIP_COUNT = 10


def select_clips(clips, trained, count=None):
    """The clips of the behaviours `trained` (ids); with `count`, that many spread evenly over them (the
    paper's 10 training clips), balanced between the behaviours."""
    groups = [[c for c in clips if c.behaviour == name] for name in trained]
    if count is None:
        return [c for group in groups for c in group]
    chosen = []
    for k, group in enumerate(groups):
        share = count // len(groups) + (1 if k < count % len(groups) else 0)
        picks = np.unique(np.linspace(0, len(group) - 1, min(share, len(group))).round().astype(int))
        chosen += [group[i] for i in picks]
    return chosen


def generate_descriptions(agent, env, objectives, bounds=spaces.DEFAULT_ACTION_BOUNDS):
    """Deterministic rollouts for a list of (N_i, O) objectives -> list of (N_i, 42) descriptions."""
    actions = rollout_actions(agent, objectives, deterministic=True)
    rotvecs = spaces.decode_action(np.concatenate(actions), bounds)  # (sum N, 15, 3)
    descriptions = np.asarray(env.evaluate(rotvecs).descriptions)  # (sum N, 42)
    return np.split(descriptions, np.cumsum([len(a) for a in actions])[:-1])


def evaluate_clips(agent, env, clips, references, bounds=spaces.DEFAULT_ACTION_BOUNDS, objective=None):
    """score_descriptions of `agent`'s deterministic rollouts on each clip's request: objective(clip,
    frame_count=None) -> (N, O) (Trainer.request_objective plays a wave at the rhythm the agent draws
    for it, as the add-on does; None: the clip's own objective in the agent's space)."""
    agent.eval()
    objective = objective or partial(clip_objective, agent.space)
    generated = generate_descriptions(agent, env, [objective(clip) for clip in clips], bounds)
    return score_descriptions(clips, generated, references)


def score_motions(env, motions, clips, references):
    """score_descriptions of generated (F_i, 15, 3) action rotations `motions`, one per clip of `clips` (the
    baselines' and the agents' answers alike), played through `env` in one batch."""
    ends = np.cumsum([len(m) for m in motions])[:-1]
    descriptions = np.split(np.asarray(env.evaluate(np.concatenate(motions)).descriptions), ends)
    return score_descriptions(clips, descriptions, references)


def clip_row(clip, generated, reference):
    """One clip's figures from generated and reference descriptions (F, 42): name, behaviour, score,
    smoothness, aligned_score and the behaviour measures (pointing ones only when the clip has a target)."""
    behaviour = clip.behaviour
    positions = spaces.description_joint_positions(generated)
    reference_positions = spaces.description_joint_positions(reference)
    row = {"name": getattr(clip, "name", ""), "behaviour": behaviours.key(behaviour),
           "score": float(metrics.score(positions, reference_positions)),
           "smoothness": float(metrics.smoothness(positions)),
           "aligned_score": behaviour_metrics.aligned_score(positions, reference_positions)}
    target = clip_target(clip)
    if target is not None or clip.behaviour_kind == behaviours.INTENSITY:
        row.update(behaviour_metrics.compare(generated, reference, clip.declared, clip.arm, target))
    else:  # a pointing clip without a target (real capture): its elevation only
        row.update({f"elevation_{k}": v for k, v in behaviour_metrics.raise_lower(
            positions, reference_positions, clip.arm).items()})
    return row


def score_descriptions(clips, descriptions, references):
    """The one scorer: {'score', 'smoothness', 'by_behaviour': {behaviour: summarise's entry}, 'clips':
    [clip_row]} of generated (F_i, 42) `descriptions` against each clip's own FK (references:
    motion.fk.ClipReferences): means over the clips, per behaviour, per clip."""
    rows = [
        clip_row(clip, generated, references.get(clip)[0]) for clip, generated in zip(clips, descriptions, strict=True)
    ]
    return {"score": float(np.mean([r["score"] for r in rows])),
            "smoothness": float(np.mean([r["smoothness"] for r in rows])),
            "by_behaviour": summarise(rows), "clips": rows}


def evaluate_seen_unseen(trainer, session):
    """Held-out (unseen) and SEEN_CLIP_COUNT training (seen) clips of the trainer's behaviour(s): {split:
    evaluate_clips's result} for each split that has clips (a library whose every clip is "train" has no
    'unseen')."""
    unseen = select_clips(session.test_clips, trainer.trained)
    seen = select_clips(session.train_clips, trainer.trained, SEEN_CLIP_COUNT)
    return {split: evaluate_clips(trainer.played_agent, session.env, clips, session.references, trainer.bounds,
                                  trainer.request_objective)
            for split, clips in (("unseen", unseen), ("seen", seen)) if clips}


def length_flexibility(agent, env, clips, training_clips, scales, bounds=spaces.DEFAULT_ACTION_BOUNDS,
                       objective=None):
    """Section 4.4: mean smoothness of each clip's gesture time-scaled to `scale` x the average
    length of its behaviour's training clips -> {behaviour: {scale: smoothness}} for each scale."""
    agent.eval()
    objective = objective or partial(clip_objective, agent.space)
    average = {}
    for clip in training_clips:
        average.setdefault(clip.behaviour, []).append(len(clip.rotvecs))
    result = {}
    for behaviour in sorted({c.behaviour for c in clips}):
        group = [c for c in clips if c.behaviour == behaviour]
        mean_length = float(np.mean(average[behaviour]))
        smoothness = result[behaviours.key(behaviour)] = {}
        for scale in scales:
            frames = max(2, int(round(scale * mean_length)))
            generated = generate_descriptions(agent, env, [objective(c, frames) for c in group], bounds)
            smoothness[f"{scale:g}"] = float(np.mean([metrics.smoothness(spaces.description_joint_positions(d))
                                                             for d in generated]))
    return result
