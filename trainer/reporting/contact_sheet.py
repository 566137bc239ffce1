"""Contact sheet of library clips: key frames of a few clips, front and side views, as one PNG
(`python -m trainer.scripts.contact_sheet`).

Draws the canonical skeleton (numpy FK, which matches Blender's pose evaluation) as a stick body,
with the wrist's path over the whole clip as a faint trail, and for the target behaviours the index
finger's line. Rows: point high, point across the body, small wave, big wave, "this way" out to the side,
a big raised hand.
"""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rlanimate_addon.core import behaviours, frame_rate, skeleton  # noqa: E402
from trainer.motion import fk  # noqa: E402
from trainer.motion.library_plan import DEFAULT_SEED, plan_library  # noqa: E402
from trainer.motion.synthesis import synthesise  # noqa: E402
from trainer.paths import CONTACT_SHEET  # noqa: E402

_INDEX = {name: i for i, name in enumerate(skeleton.BONE_NAMES)}
_PARENT = [(_INDEX[b.name], _INDEX[b.parent]) for b in skeleton.BONES if b.parent is not None]
_WIDTH = {"Spine": 9, "Spine1": 9, "Spine2": 9, "Neck": 5, "Arm": 5, "ForeArm": 4, "UpLeg": 6, "Leg": 5}


def _width(name):
    for key, width in _WIDTH.items():
        if name.endswith(key):
            return width
    return 1.2 if "Hand" in name and name[-1].isdigit() else 3


def pick_clips(seed=DEFAULT_SEED):
    """(title, PlannedClip) for point high, point across, small wave, big wave, guide out to the side and
    big raised hand (training clips)."""
    plan = [p for p in plan_library(seed) if p.split == "train"]
    points, waves, guides, raises = ([p for p in plan if behaviours.SHIPPED[p.spec.behaviour] == action]
                                     for action in (behaviours.AIMS, behaviours.OSCILLATES, behaviours.PRESENTS,
                                                    behaviours.RAISES))

    def across(p):  # how far across the body the target lies
        return -p.spec.target[0] if p.spec.arm == "LEFT" else p.spec.target[0]

    return [("point high", max(points, key=lambda p: p.spec.target[2])),
            ("point across", max(points, key=across)),
            ("wave small", min(waves, key=lambda p: p.spec.exaggeration)),
            ("wave big", max(waves, key=lambda p: p.spec.exaggeration)),
            ("this way, side", min(guides, key=across)),
            ("raise hand big", max(raises, key=lambda p: p.spec.exaggeration))]


def key_frames(clip, wrist_x):
    """Six frames that show the motion: for a held gesture (point, guide, raise hand) start, wind-up,
    mid-stroke, hold, mid-return, end; for waving start, mid-raise, three swing extremes (from the wrist's
    sideways path), mid-lowering."""
    p = clip.phases
    if "hold" in p:
        out, _, back = (p[name] for name in p)  # the stroke (or raise), the hold, the return (or lowering)
        return [0, out[0], (out[0] + out[1]) // 2, p["hold"][0], (back[0] + back[1]) // 2, clip.frames - 1]
    first, last = p["wave"]
    sway = wrist_x[first:last + 1]
    turns = [first + i for i in range(1, len(sway) - 1)
             if (sway[i] - sway[i - 1]) * (sway[i + 1] - sway[i]) <= 0]
    middle = len(turns) // 2
    return [0, (p["raise"][0] + p["raise"][1]) // 2, *turns[middle - 1:middle + 2],
            (p["lower"][0] + p["lower"][1]) // 2]


def _draw(ax, heads, frame, view, trail, target):
    axes = (0, 2) if view == "front" else (1, 2)
    flip = -1.0 if view == "side" else 1.0  # side view: the character faces right

    def xy(points):
        points = np.atleast_2d(points)
        return flip * points[:, axes[0]], points[:, axes[1]]

    pose = heads[frame]
    for child, parent in _PARENT:
        name = skeleton.BONE_NAMES[child]
        if name.endswith(("Eye", "_End")):
            continue
        x, y = xy(pose[[parent, child]])
        left = "Left" in name
        color = "#2b5d9b" if left else "#b5482f" if "Right" in name else "#444444"
        ax.plot(
            x, y, color=color, lw=_width(name), solid_capstyle="round", alpha=0.95 if left or view == "front" else 0.8
        )
    hx, hy = xy(0.5 * (pose[_INDEX["Head"]] + pose[_INDEX["HeadTop_End"]]))
    ax.add_patch(plt.Circle((hx[0], hy[0]), 0.1, color="#444444", fill=False, lw=2))
    eye = pose[_INDEX["LeftEye"]]
    ex, ey = xy(eye)
    ax.plot(ex, ey, "o", color="#444444", ms=2)
    tx, ty = xy(trail)
    ax.plot(tx, ty, color="#888888", lw=0.7, alpha=0.6)
    if target is not None:
        base, tip = pose[_INDEX[target[1] + "HandIndex1"]], pose[_INDEX[target[1] + "HandIndex4"]]
        ray = np.stack([base, base + 0.9 * (tip - base) / np.linalg.norm(tip - base)])
        rx, ry = xy(ray)
        ax.plot(rx, ry, ":", color="#2a9d3a", lw=1)
    ax.set_xlim(-0.95, 0.95)
    ax.set_ylim(0.55, 2.3)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def render(out=CONTACT_SHEET, seed=DEFAULT_SEED):
    chosen = pick_clips(seed)
    columns = 6
    fig, axes = plt.subplots(2 * len(chosen), columns, figsize=(columns * 1.9, 2 * len(chosen) * 1.75), dpi=110)
    for row, (title, planned) in enumerate(chosen):
        clip = synthesise(planned.spec)
        fingers = {bone: rotvecs for bone, rotvecs in clip.rotvecs.items() if bone not in skeleton.ACTION_JOINTS}
        heads = fk.bone_heads(clip.action_rotvecs(), fingers)  # (F, B, 3)
        side = skeleton.ARM_PREFIX[planned.spec.arm]
        trail = heads[:, _INDEX[side + "HandIndex1"]]
        target = ("ray", side) if planned.spec.target is not None else None
        label = (f"target {np.round(planned.spec.target, 2).tolist()}" if target
                 else f"exaggeration {planned.spec.exaggeration:.2f}")
        for col, frame in enumerate(key_frames(clip, trail[:, 0])):
            for v, view in enumerate(("front", "side")):
                ax = axes[2 * row + v, col]
                _draw(ax, heads, frame, view, trail, target)
                ax.set_title(f"{frame / clip.fps:.2f}s" + (f"  {view}" if col == 0 else ""), fontsize=7, pad=2)
        axes[2 * row, 0].set_ylabel(f"{title}\n{planned.spec.arm.lower()} arm", fontsize=8)
        axes[2 * row + 1, 0].set_ylabel(label, fontsize=6)
    return _save(fig, "RLAnimate sample clips: key frames (front / side; grey = index-base path, "
                      "green dots = finger line)", 0.98, out)


def generated_sheet(rows, out, title, fps=frame_rate.AGENT_FPS, frame_labels=False):
    """One PNG of rendered frames: rows [(row title, [(frame offset, png path)])], a column per key frame, each
    titled with its time (or, with frame_labels, its frame number)."""
    columns = max(len(frames) for _, frames in rows)
    fig, axes = plt.subplots(len(rows), columns, figsize=(columns * 1.9, len(rows) * 2.0), dpi=110, squeeze=False)
    for (row_title, frames), row_axes in zip(rows, axes, strict=True):
        for ax, (offset, path) in zip(row_axes, frames, strict=False):  # a shorter row leaves axes empty
            ax.imshow(plt.imread(str(path)))
            ax.set_title(f"frame {offset}" if frame_labels else f"{offset / fps:.2f}s", fontsize=7, pad=2)
        for ax in row_axes:
            ax.set_xticks([])
            ax.set_yticks([])
        row_axes[0].set_ylabel(row_title, fontsize=7)
    return _save(fig, title, 0.97, out)


def _save(fig, title, top, out):
    """Title the sheet, leave `top` of the height to the plots, write it to `out` (a PNG) and return the path."""
    fig.suptitle(title, fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, top))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    plt.close(fig)
    return out
