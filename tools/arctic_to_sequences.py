#!/usr/bin/env python3
"""Convert a user's ARCTIC download to a bimart data set folder.

    python3 tools/arctic_to_sequences.py ARCTIC OUT \\
        --mano-left mano_left.npz --mano-right mano_right.npz \\
        [--test-subjects s03] [--subjects s01,s02,...] [--objects box,laptop,...]

Needs numpy only (no torch, scipy or smplx). ARCTIC is the folder holding raw_seqs/ and
meta/ (in the official download: arctic_data/data). Read from it:

    raw_seqs/<subject>/<seq>.mano.npy     pickled dict {'left': {...}, 'right': {...}}, each with
                                          rot [N,3], pose [N,45] (relative to MANO's mean
                                          pose), trans [N,3] (m), shape [10] or [N,10]
    raw_seqs/<subject>/<seq>.object.npy   [N,7] = angle, axis-angle root, translation (mm)
    meta/object_vtemplates/<object>/top.obj, bottom.obj   (mm)

--mano-left/--mano-right are the user's MANO models converted by tools/mano_to_npz.py
(convert MANO_LEFT.pkl WITHOUT --fix-left-shapedirs: ARCTIC was fitted with the unfixed
file); only their hands_mean is used here, to make the finger pose flat.

Written (docs/formats.md, sections "Sequence" and "ARCTIC sequences"):

    OUT/objects/<object>/top.obj, bottom.obj   copied from the templates (still mm)
    OUT/sequences/<subject>_<seq>.npz          bimart sequence files, 30 fps, metres
    OUT/manifest.json                          train/test split by subject, written last

Every input is read and checked before anything is written; problems are reported naming
the file, with exit code 2. Each file is written atomically and manifest.json last, so an
interrupted run never leaves a folder that looks like a complete data set.

The .mano.npy files are pickles (numpy.load(allow_pickle=True)): only convert downloads
you trust.
"""

import argparse
import json
import os
import shutil
import sys
import tempfile

import numpy as np

GENERATOR = "arctic_to_sequences.py"
FPS = 30
MM = 0.001  # metres per millimetre
HANDS = ("left", "right")
PARTS = ("top.obj", "bottom.obj")


class ConvertError(Exception):
    """A problem with the input: reported without a traceback, exit code 2."""


def _comma_list(text):
    return [t.strip() for t in text.split(",") if t.strip()] if text else []


def _float_array(value, where, shape):
    """`value` as a finite float64 array of `shape` (None = any size) that survives float32."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ConvertError(f"{where} is not a numeric array ({e})") from e
    if a.ndim != len(shape) or any(s is not None and a.shape[i] != s for i, s in enumerate(shape)):
        want = "[" + ", ".join("N" if s is None else str(s) for s in shape) + "]"
        raise ConvertError(f"{where} has shape {list(a.shape)}, expected {want}")
    bad = ~np.isfinite(a.astype(np.float32))
    if bad.any():
        first = np.argwhere(bad)[0]
        raise ConvertError(f"{where} has a value that is not finite (or too large for float32) "
                           f"at index {tuple(int(i) for i in first)}")
    return a


# --- inputs -------------------------------------------------------------------------------


def load_hands_mean(path, side):
    """hands_mean [45] of a bimart hand model (.npz, docs/formats.md "Hand model")."""
    if not os.path.isfile(path):
        raise ConvertError(f"{path}: no such hand model file (--mano-{side})")
    try:
        with np.load(path, allow_pickle=False) as npz:
            keys = set(npz.files)
            if "hands_mean" not in keys:
                raise ConvertError(f"{path}: not a bimart hand model: no key 'hands_mean' "
                                   f"(keys: {', '.join(sorted(keys))}); convert MANO_{side.upper()}.pkl "
                                   "with tools/mano_to_npz.py")
            mean = _float_array(npz["hands_mean"], f"{path}: 'hands_mean'", (45,))
            if "is_right" in keys and bool(npz["is_right"]) != (side == "right"):
                other = "right" if side == "left" else "left"
                raise ConvertError(f"{path}: is a {other} hand model, given as --mano-{side}")
    except ConvertError:
        raise
    except Exception as e:  # noqa: BLE001 - a broken or foreign file
        raise ConvertError(f"{path}: not a readable .npz hand model ({e})") from e
    return mean


def load_mano_file(path, shown):
    """{'left': {...}, 'right': {...}} of float64 arrays from an ARCTIC .mano.npy."""
    try:
        raw = np.load(path, allow_pickle=True)
    except Exception as e:  # noqa: BLE001 - a broken file
        raise ConvertError(f"{shown}: not a readable .npy file ({e})") from e
    if not (isinstance(raw, np.ndarray) and raw.dtype == object and raw.shape == ()):
        raise ConvertError(f"{shown}: expected a pickled dict with 'left' and 'right', got an array "
                           f"of shape {list(getattr(raw, 'shape', []))}")
    data = raw.item()
    if not isinstance(data, dict):
        raise ConvertError(f"{shown}: expected a pickled dict with 'left' and 'right', got "
                           f"{type(data).__name__}")
    missing = [h for h in HANDS if h not in data]
    if missing:
        raise ConvertError(f"{shown}: no '{' and '.join(missing)}' hand (keys: "
                           f"{', '.join(sorted(map(str, data)))}); both hands are needed")
    hands = {}
    for h in HANDS:
        d = data[h]
        if not isinstance(d, dict):
            raise ConvertError(f"{shown}: '{h}' is a {type(d).__name__}, expected a dict")
        for key in ("rot", "pose", "trans", "shape"):
            if key not in d:
                raise ConvertError(f"{shown}: '{h}' has no '{key}' (keys: {', '.join(sorted(map(str, d)))})")
        w = f"{shown}: '{h}' '%s'"
        rot = _float_array(d["rot"], w % "rot", (None, 3))
        pose = _float_array(d["pose"], w % "pose", (None, 45))
        trans = _float_array(d["trans"], w % "trans", (None, 3))
        shape = np.asarray(d["shape"])
        shape = _float_array(shape, w % "shape", (10,) if shape.ndim == 1 else (None, 10))
        if shape.ndim == 2:
            if shape.shape[0] == 0:
                raise ConvertError(f"{shown}: '{h}' 'shape' has no rows")
            shape = shape.mean(axis=0)  # one shape per sequence (ARCTIC's rows are equal)
        n = {len(rot), len(pose), len(trans)}
        if len(n) != 1:
            raise ConvertError(f"{shown}: '{h}' frame counts disagree: rot {len(rot)}, pose {len(pose)}, "
                               f"trans {len(trans)}")
        hands[h] = {"rot": rot, "pose": pose, "trans": trans, "shape": shape}
    return hands


def load_object_file(path, shown):
    try:
        raw = np.load(path, allow_pickle=False)
    except Exception as e:  # noqa: BLE001 - a broken file, or a pickle where numbers belong
        raise ConvertError(f"{shown}: not a readable numeric .npy file ({e})") from e
    return _float_array(raw, shown, (None, 7))


# --- discovery ----------------------------------------------------------------------------


class Item:
    """One ARCTIC sequence to convert."""

    def __init__(self, subject, seq, mano_path, object_path):
        self.subject = subject
        self.seq = seq
        self.mano_path = mano_path
        self.object_path = object_path
        parts = seq.split("_")
        self.object = parts[0]
        self.kind = parts[1] if len(parts) > 1 else ""
        self.name = f"{subject}_{seq}"
        self.rel_path = f"sequences/{self.name}.npz"
        self.split = None
        self.arrays = None
        self.frames = 0


def discover(root, subjects, objects):
    raw_dir = os.path.join(root, "raw_seqs")
    tmpl_dir = os.path.join(root, "meta", "object_vtemplates")
    for d, what in ((root, "the ARCTIC folder"), (raw_dir, "ARCTIC's raw_seqs folder"),
                    (tmpl_dir, "ARCTIC's object templates folder")):
        if not os.path.isdir(d):
            raise ConvertError(f"{d}: no such folder ({what}; give the folder that holds "
                               "raw_seqs/ and meta/)")
    present = sorted(e for e in os.listdir(raw_dir) if os.path.isdir(os.path.join(raw_dir, e)))
    for s in subjects:
        if s not in present:
            raise ConvertError(f"{os.path.join(raw_dir, s)}: no such subject folder (--subjects; "
                               f"present: {', '.join(present) or 'none'})")
    items = []
    for subject in (subjects or present):
        sdir = os.path.join(raw_dir, subject)
        for f in sorted(os.listdir(sdir)):
            if not f.endswith(".mano.npy"):
                continue
            seq = f[: -len(".mano.npy")]
            item = Item(subject, seq, os.path.join(sdir, f), os.path.join(sdir, seq + ".object.npy"))
            if objects and item.object not in objects:
                continue
            items.append(item)
    for o in objects:
        if not any(i.object == o for i in items):
            raise ConvertError(f"--objects {o}: no sequence of that object in {raw_dir}"
                               + (f" for subjects {', '.join(subjects)}" if subjects else ""))
    if not items:
        raise ConvertError(f"{raw_dir}: no <subject>/<seq>.mano.npy files found")
    templates = {}
    for item in items:
        if item.object in templates:
            continue
        t = os.path.join(tmpl_dir, item.object)
        for part in PARTS:
            p = os.path.join(t, part)
            if not os.path.isfile(p):
                raise ConvertError(f"{item.mano_path}: unknown object '{item.object}': no "
                                   f"template {p}")
        templates[item.object] = t
    return items, templates


def read_item(item, means):
    """Reads, checks and converts one sequence into item.arrays."""
    mano_shown = item.mano_path
    obj_shown = item.object_path
    if not os.path.isfile(item.object_path):
        raise ConvertError(f"{obj_shown}: missing (the object states of {mano_shown})")
    hands = load_mano_file(item.mano_path, mano_shown)
    states = load_object_file(item.object_path, obj_shown)
    n = len(states)
    counts = {h: len(hands[h]["rot"]) for h in HANDS}
    if any(c != n for c in counts.values()):
        raise ConvertError(f"{mano_shown}: frame counts disagree with {obj_shown}: left {counts['left']}, "
                           f"right {counts['right']}, object {n}")
    if n < 1:
        raise ConvertError(f"{mano_shown}: the sequence has no frames")
    states = states.copy()
    states[:, 4:7] *= MM  # object root translation mm -> m
    arrays = {
        "format_version": np.array(1, dtype=np.int64),
        "name": np.array(item.name),
        "object": np.array(f"../objects/{item.object}"),
        "category": np.array(item.object),
        "kind": np.array(item.kind),
        "fps": np.array(float(FPS), dtype=np.float64),
        "object_states": states.astype(np.float32),
    }
    for h in HANDS:
        d = hands[h]
        flat = d["pose"] + means[h][None, :]  # ARCTIC's pose is relative to hands_mean
        arrays[f"{h}_rot"] = d["rot"].astype(np.float32)
        arrays[f"{h}_pose"] = flat.astype(np.float32)
        arrays[f"{h}_trans"] = d["trans"].astype(np.float32)
        arrays[f"{h}_shape"] = d["shape"].astype(np.float32)
    for k, a in arrays.items():
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            raise ConvertError(f"{mano_shown}: '{k}' is not finite after conversion")
    item.arrays = arrays
    item.frames = n


# --- output -------------------------------------------------------------------------------


def _atomic(path, write):
    """Calls write(file object) on a temporary file beside `path`, then renames it."""
    folder = os.path.dirname(path)
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".arctic_to_sequences.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def _copy_atomic(src, dst):
    def write(f):
        with open(src, "rb") as s:
            shutil.copyfileobj(s, f)
    _atomic(dst, write)


def previous_manifest(out):
    """The manifest of an earlier run of this tool in `out` ({} when there is none yet, None
    for a new folder); refuses a folder holding anything else."""
    if not os.path.exists(out):
        return None
    if not os.path.isdir(out):
        raise ConvertError(f"{out}: exists and is not a folder")
    entries = {e for e in os.listdir(out) if not e.startswith(".")}
    path = os.path.join(out, "manifest.json")
    if "manifest.json" not in entries:
        if entries <= {"objects", "sequences"}:
            return {}  # empty, or an interrupted run of this tool (the manifest comes last)
    else:
        try:
            with open(path, encoding="utf-8") as f:
                m = json.load(f)
            if isinstance(m, dict) and m.get("generator") == GENERATOR:
                return m
        except (OSError, ValueError):
            pass
    raise ConvertError(f"{out}: the output folder is not empty and holds no earlier output of "
                       f"{GENERATOR} (manifest.json); give a new or empty folder")


def write_dataset(out, items, templates, test_subjects, old):
    manifest_path = os.path.join(out, "manifest.json")
    os.makedirs(out, exist_ok=True)
    if os.path.exists(manifest_path):
        os.remove(manifest_path)  # the folder is no data set until the new manifest is in place
    used = sorted({i.object for i in items})
    for o in used:
        for part in PARTS:
            _copy_atomic(os.path.join(templates[o], part), os.path.join(out, "objects", o, part))
    for k, item in enumerate(items, 1):
        _atomic(os.path.join(out, item.rel_path), lambda f, a=item.arrays: np.savez_compressed(f, **a))
        print(f"[{k}/{len(items)}] {item.rel_path}: {item.frames} frames ({item.split})", flush=True)
    splits = {o: sorted({i.split for i in items if i.object == o}, key=("train", "test").index) for o in used}
    manifest = {
        "format": "bimart-dataset",
        "version": 1,
        "generator": GENERATOR,
        "seed": 0,
        "fps": FPS,
        "train": sorted(i.rel_path for i in items if i.split == "train"),
        "test": sorted(i.rel_path for i in items if i.split == "test"),
        "objects": [{"name": o, "path": f"objects/{o}", "category": o, "split": "+".join(splits[o])}
                    for o in used],
    }
    text = json.dumps(manifest, indent=2) + "\n"
    _atomic(manifest_path, lambda f: f.write(text.encode("utf-8")))
    # Sequences an earlier run listed that this one did not write (other filters).
    if old:
        now = set(manifest["train"]) | set(manifest["test"])
        for rel in set(old.get("train", [])) | set(old.get("test", [])):
            p = os.path.normpath(os.path.join(out, str(rel)))
            if isinstance(rel, str) and rel.startswith("sequences/") and rel not in now and os.path.isfile(p):
                os.remove(p)
    return manifest


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="See docs/formats.md, section \"ARCTIC sequences\".")
    p.add_argument("arctic", help="ARCTIC data folder holding raw_seqs/ and meta/object_vtemplates/")
    p.add_argument("output", help="data set folder to write (new, empty, or an earlier output of this tool)")
    p.add_argument("--mano-left", required=True, help="converted left MANO model (.npz, tools/mano_to_npz.py)")
    p.add_argument("--mano-right", required=True, help="converted right MANO model (.npz)")
    p.add_argument("--test-subjects", default="s03",
                   help="comma list of subjects for the test split (default: s03, ARCTIC's held-out subject)")
    p.add_argument("--subjects", default="", help="comma list: convert only these subjects (default: all)")
    p.add_argument("--objects", default="", help="comma list: convert only these objects (default: all)")
    args = p.parse_args(argv)
    root = args.arctic
    try:
        test_subjects = set(_comma_list(args.test_subjects))
        means = {"left": load_hands_mean(args.mano_left, "left"),
                 "right": load_hands_mean(args.mano_right, "right")}
        items, templates = discover(root, _comma_list(args.subjects), _comma_list(args.objects))
        old = previous_manifest(args.output)
        print(f"arctic_to_sequences: reading {len(items)} sequences from {os.path.join(root, 'raw_seqs')}",
              flush=True)
        for item in items:
            read_item(item, means)
            item.split = "test" if item.subject in test_subjects else "train"
    except ConvertError as e:
        print(f"arctic_to_sequences: error: {e}", file=sys.stderr)
        return 2
    if not any(i.split == "test" for i in items):
        print(f"arctic_to_sequences: warning: no sequence of the test subjects "
              f"({', '.join(sorted(test_subjects)) or 'none'}); the test split is empty", file=sys.stderr)
    if not any(i.split == "train" for i in items):
        print("arctic_to_sequences: warning: every sequence is a test subject's; the train split is empty",
              file=sys.stderr)
    try:
        manifest = write_dataset(args.output, items, templates, test_subjects, old)
    except OSError as e:
        print(f"arctic_to_sequences: error: cannot write {e.filename or args.output}: {e.strerror}",
              file=sys.stderr)
        return 1
    frames = sum(i.frames for i in items)
    print(f"arctic_to_sequences: wrote {args.output}: {len(items)} sequences (train {len(manifest['train'])}, "
          f"test {len(manifest['test'])}), objects {', '.join(o['name'] for o in manifest['objects'])}, {frames} frames "
          f"({frames / FPS / 60:.1f} min at {FPS} fps)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
