"""`trainer/train.py --clips FOLDER` on a folder of takes without a manifest: the labels table, the editable
manifest, the hold-out by take, training, and the comparison with retrieval on the held-out takes, both requests."""
import json
import shutil

import pytest

from rlanimate_addon.core.errors import RLAnimateError
from trainer.experiments import capture
from trainer.motion import capture_folder
from trainer.paths import CLIP_DIR, REALMOCAP_DIR
from trainer.scripts import train

#: Twelve takes of the sample library: three per behaviour and arm, labelled only by their names and motion here.
TAKES = [f"{behaviour}_{arm}_{k:03d}.fbx" for behaviour in ("point", "wave") for arm in ("left", "right")
         for k in range(3)]


def test_a_folder_of_takes_is_labelled_held_out_trained_and_compared_with_retrieval(tmp_path, capsys):
    folder, output = tmp_path / "takes", tmp_path / "run"
    folder.mkdir()
    for name in TAKES:
        shutil.copy(CLIP_DIR / name, folder / name)
    assert train.main(["train.py", "--clips", str(folder), "--output", str(output), "--preset", "debug", "--epochs",
                       "2", "--eval-every", "0", "--quiet"]) == 0
    shown = capsys.readouterr()
    assert "| take | behaviour (kind) | arm | label | tempo | frames | split | notes |" in shown.out
    assert f"edit it and train on it with --clips {output / 'manifest.json'}" in shown.err
    written = json.loads((output / "manifest.json").read_text())["clips"]
    assert [entry["behaviour"] for entry in written] == ["POINT"] * 6 + ["WAVE"] * 6
    assert all(entry["arm"] == ("LEFT" if "_left_" in entry["file"] else "RIGHT") for entry in written)
    assert all(0.0 <= entry["exaggeration"] <= 1.0 and entry["tempo_hz"] > 1.0 for entry in written[6:])
    held = [entry["file"].rsplit("/", 1)[1] for entry in written if entry["split"] == "test"]
    assert len(held) == 4 and {name.rsplit("_", 1)[0] for name in held} == {
        "point_left", "point_right", "wave_left", "wave_right"}, "one of each behaviour and arm's three"
    report = json.loads((output / "capture_report.json").read_text())
    assert (report["training_takes"], report["held_out_takes"], report["run"]["preset"]) == (8, 4, "debug")
    assert set(report["behaviours"]) == {"point", "wave"}
    assert set(report["behaviours"]["point"]) == {"paper"} and set(report["behaviours"]["wave"]) == {"paper", "tempo"}
    for requests in report["behaviours"].values():
        for methods in requests.values():
            assert set(methods) == {"rlanimate", "nearest_clip"}
            assert sorted(c["name"] for c in methods["rlanimate"]["clips"]) == sorted(
                c["name"] for c in methods["nearest_clip"]["clips"]) and len(methods["rlanimate"]["clips"]) == 2
    page = (output / "capture_report.md").read_text()
    assert "| wave | tempo asked | 2 |" in page and "| point | label only (the paper's) | 2 |" in page
    assert "own aim" in page and "waves accepted" in page, "each behaviour's own measures"
    assert "## Labels" in page and "wave_right_000.fbx" in page
    assert (output / "capture_hand_paths.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(report["hand_paths"]) == 2 and all("tempo asked" in title for title in report["hand_paths"])


def test_a_folder_of_waves_alone_trains_a_wave_agent(tmp_path):
    folder = tmp_path / "wave"
    folder.mkdir()
    for name in TAKES[6:]:
        shutil.copy(CLIP_DIR / name, folder / name)
    assert train.main(["train.py", "--clips", str(folder), "--output", str(tmp_path / "run"), "--preset", "debug",
                       "--epochs", "1", "--eval-every", "0", "--quiet"]) == 0
    report = json.loads((tmp_path / "run" / "capture_report.json").read_text())
    assert list(report["behaviours"]) == ["wave"] and report["held_out_takes"] == 2


@pytest.mark.skipif(not (REALMOCAP_DIR / "wave").is_dir(), reason=f"the real capture is not at {REALMOCAP_DIR}")
def test_real_takes_are_labelled_as_waves_of_the_arm_their_names_give(tmp_path):
    folder = tmp_path / "wave"
    folder.mkdir()
    for name in ("dataset-2_wave-left-hand_feminine_001.bvh", "dataset-2_wave-right-hand_active_002.bvh",
                 "dataset-2_wave-right-hand_masculine_003.bvh"):
        (folder / name).symlink_to(REALMOCAP_DIR / "wave" / name)
    labelled = capture.label_folder(str(folder), str(tmp_path / "run"), share=0.0)
    labels = {label.name.split("_")[2]: label for label in labelled.labels}
    assert [(label.behaviour, label.arm, label.notes) for label in labels.values()] == [
        ("WAVE", "LEFT", []), ("WAVE", "RIGHT", []), ("WAVE", "RIGHT", [])]
    assert labels["feminine"].exaggeration < 0.2 < 0.9 < labels["active"].exaggeration
    assert 0.6 < labels["masculine"].tempo < 1.6 and labels["active"].tempo > 1.5


def test_only_a_folder_without_a_manifest_is_labelled_and_it_trains_the_real_capture_recipe(tmp_path):
    assert capture.is_capture_folder(str(tmp_path)) and not capture.is_capture_folder(None)
    (tmp_path / "manifest.json").write_text("{}")
    assert not capture.is_capture_folder(str(tmp_path)) and not capture.is_capture_folder(str(tmp_path / "x.json"))
    given = train.parse_settings(["train.py", "--output", "run", "--epochs", "7"]).run
    labels = [capture_folder.TakeLabel(f"/t/{name}.bvh", behaviour, "intensity", "LEFT", 90, 30.0, 0.5, split=split)
              for name, behaviour, split in (("a", "WAVE", "train"), ("b", "HELLO", "test"), ("c", "WAVE", "test"))]
    labelled = capture.Labelled("takes", tmp_path / "run" / "manifest.json", labels)
    chosen = capture.capture_settings(given, labelled)
    assert (chosen.clips, chosen.preset, chosen.epochs) == (str(tmp_path / "run" / "manifest.json"), "end_chunks", 7)
    assert chosen.behaviour == "wave", "the behaviours its training takes have: a folder of waves trains waves"


def test_a_folder_without_takes_or_a_bad_share_is_refused_before_anything_is_imported(tmp_path):
    with pytest.raises(RLAnimateError, match="holds no .bvh or .fbx takes"):
        capture.label_folder(str(tmp_path), str(tmp_path / "run"))
    (tmp_path / "wave_left_001.bvh").write_text("not read")
    with pytest.raises(RLAnimateError, match="--hold-out 1"):
        capture.label_folder(str(tmp_path), str(tmp_path / "run"), share=1.0)
