#!/usr/bin/env python3
"""Convert an official MANO hand model (MANO_RIGHT.pkl / MANO_LEFT.pkl) to bimart's .npz.

    python3 tools/mano_to_npz.py MANO_RIGHT.pkl mano_right.npz
    python3 tools/mano_to_npz.py MANO_LEFT.pkl mano_left.npz [--fix-left-shapedirs]

Needs numpy only. The official files are Python 2 pickles holding chumpy arrays and a
scipy.sparse J_regressor; this script reads them without chumpy or scipy by mapping those
classes to small stand-ins that keep the pickled state, then densifies it.

The output layout (keys, dtypes, shapes, units) is documented in docs/formats.md,
section "Hand model (.npz)". Surface keypoints (keypoint_verts) are not written: bimart
computes them from the mesh.

--fix-left-shapedirs: the official LEFT model's shapedirs[:, 0, :] (the x components of
the shape blend shapes) have the wrong sign. Off by default, because data fitted with the
unfixed file (e.g. ARCTIC) is only reproduced by the unfixed file; turn it on for new fits.
"""

import argparse
import os
import pickle
import sys
import tempfile

import numpy as np

# MANO fingertip vertex ids (thumb, index, middle, ring, pinky); the left model uses the
# same ids as the right.
MANO_FINGERTIPS = (744, 320, 443, 554, 671)
NUM_JOINTS = 16
UINT32_MAX = 4294967295


class ConvertError(Exception):
    pass


class _StandIn:
    """Takes the place of a chumpy or scipy.sparse object and keeps its pickled state."""

    module = ""
    name = ""

    def __init__(self, *args, **kwargs):
        self.args = args
        self.state = None

    def __setstate__(self, state):
        self.state = state


def _stand_in(module, name):
    return type(name, (_StandIn,), {"module": module, "name": name})


class _ManoUnpickler(pickle.Unpickler):
    def find_class(self, module, name):
        if module == "chumpy" or module.startswith("chumpy.") or module.startswith("scipy.sparse"):
            return _stand_in(module, name)
        return super().find_class(module, name)


def _state_dict(obj):
    state = obj.state
    if isinstance(state, tuple) and len(state) == 2 and isinstance(state[1], dict):
        state = state[1]  # (None, slots) form
    return state if isinstance(state, dict) else {}


def _dense(obj, key, path):
    """A plain numpy array from an ndarray, a chumpy stand-in or a sparse stand-in."""
    if isinstance(obj, np.ndarray):
        return obj
    if isinstance(obj, _StandIn):
        state = _state_dict(obj)
        if obj.module.startswith("scipy.sparse"):
            return _densify_sparse(obj, state, key, path)
        for field in ("x", "a", "r"):
            if field in state:
                return _dense(state[field], key, path)
        raise ConvertError(f"{path}: '{key}' is a {obj.module}.{obj.name} without an array "
                           f"(state keys: {sorted(state)})")
    try:
        return np.asarray(obj)
    except Exception as e:  # noqa: BLE001 - report any conversion failure
        raise ConvertError(f"{path}: '{key}' cannot be read as an array: {e}") from e


def _densify_sparse(obj, state, key, path):
    shape = state.get("_shape", state.get("shape"))
    if shape is None or not all(k in state for k in ("data", "indices", "indptr")):
        raise ConvertError(f"{path}: '{key}' is a {obj.name} without data/indices/indptr/shape")
    rows, cols = (int(s) for s in shape)
    data = np.asarray(state["data"], dtype=np.float64)
    indices = np.asarray(state["indices"], dtype=np.int64)
    indptr = np.asarray(state["indptr"], dtype=np.int64)
    dense = np.zeros((rows, cols), dtype=np.float64)
    if obj.name.startswith("csc"):
        for c in range(cols):
            lo, hi = indptr[c], indptr[c + 1]
            np.add.at(dense[:, c], indices[lo:hi], data[lo:hi])
    elif obj.name.startswith("csr"):
        for r in range(rows):
            lo, hi = indptr[r], indptr[r + 1]
            np.add.at(dense[r], indices[lo:hi], data[lo:hi])
    else:
        raise ConvertError(f"{path}: '{key}' is an unsupported sparse type {obj.name}")
    return dense


def load_mano_pickle(path):
    """The pickle's dict with every value as a plain numpy array (or left as is)."""
    try:
        with open(path, "rb") as f:
            raw = _ManoUnpickler(f, encoding="latin1").load()
    except OSError as e:
        raise ConvertError(f"cannot read '{path}': {e.strerror}") from e
    except Exception as e:  # noqa: BLE001 - a broken or foreign pickle
        raise ConvertError(f"{path}: not a readable MANO pickle ({e})") from e
    if not isinstance(raw, dict):
        raise ConvertError(f"{path}: expected a dict of arrays, got {type(raw).__name__}")
    return raw


def _get(raw, key, path, ndim, dtype=np.float64):
    if key not in raw:
        raise ConvertError(f"{path}: missing '{key}' (keys: {', '.join(sorted(map(str, raw)))})")
    a = np.ascontiguousarray(_dense(raw[key], key, path), dtype=dtype)
    if a.ndim != ndim:
        raise ConvertError(f"{path}: '{key}' has shape {a.shape}, expected {ndim} dimensions")
    return a


def convert(raw, path, is_right, fix_left_shapedirs=False, fingertips=MANO_FINGERTIPS):
    """The .npz arrays (dict) for one MANO pickle's contents."""
    v_template = _get(raw, "v_template", path, 2)
    V = v_template.shape[0]

    def expect(key, a, shape):
        if a.shape != shape:
            raise ConvertError(f"{path}: '{key}' has shape {a.shape}, expected {shape}")
        return a

    expect("v_template", v_template, (V, 3))
    shapedirs = expect("shapedirs", _get(raw, "shapedirs", path, 3), (V, 3, 10)).copy()
    posedirs = expect("posedirs", _get(raw, "posedirs", path, 3), (V, 3, 135))
    j_regressor = expect("J_regressor", _get(raw, "J_regressor", path, 2), (NUM_JOINTS, V))
    weights = expect("weights", _get(raw, "weights", path, 2), (V, NUM_JOINTS))
    kintree = expect("kintree_table", _get(raw, "kintree_table", path, 2, np.int64), (2, NUM_JOINTS))
    faces = _get(raw, "f", path, 2, np.int64)
    if faces.shape[1] != 3 or faces.min() < 0 or faces.max() >= V:
        raise ConvertError(f"{path}: 'f' must be [F, 3] vertex ids below {V}")
    components = expect("hands_components", _get(raw, "hands_components", path, 2), (45, 45))
    mean = expect("hands_mean", _get(raw, "hands_mean", path, 1), (45,))

    kintree = kintree.copy()
    if kintree[0, 0] == UINT32_MAX:
        kintree[0, 0] = -1
    if is_right and fix_left_shapedirs:
        raise ConvertError("--fix-left-shapedirs applies to the left hand only")
    if fix_left_shapedirs:
        shapedirs[:, 0, :] *= -1
    tips = np.asarray(fingertips, dtype=np.int32)
    if tips.shape != (5,) or tips.min() < 0 or tips.max() >= V:
        raise ConvertError(f"{path}: fingertip vertex ids {list(tips)} are not 5 ids below {V} "
                           "(give --fingertip-verts for a non-MANO mesh)")
    return {
        "v_template": v_template,
        "shapedirs": shapedirs,
        "posedirs": posedirs,
        "J_regressor": j_regressor,
        "weights": weights,
        "kintree_table": kintree,
        "f": faces.astype(np.int32),
        "hands_components": components,
        "hands_mean": mean,
        "fingertip_verts": tips,
        "is_right": np.array(bool(is_right)),
    }


def write_npz_atomically(arrays, out_path):
    folder = os.path.dirname(os.path.abspath(out_path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".mano_to_npz.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez_compressed(f, **arrays)
        os.replace(tmp, out_path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def side_from_name(path):
    name = os.path.basename(path).upper()
    if "LEFT" in name and "RIGHT" not in name:
        return False
    if "RIGHT" in name and "LEFT" not in name:
        return True
    return None


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("pickle", help="official MANO_RIGHT.pkl or MANO_LEFT.pkl")
    p.add_argument("output", help="the .npz to write")
    p.add_argument("--side", choices=("left", "right"),
                   help="hand side (default: from the file name, LEFT or RIGHT)")
    p.add_argument("--fix-left-shapedirs", action="store_true",
                   help="negate the left model's shapedirs[:, 0, :] (default off, see above)")
    p.add_argument("--fingertip-verts", default=",".join(map(str, MANO_FINGERTIPS)),
                   help="thumb,index,middle,ring,pinky vertex ids (default: MANO's)")
    args = p.parse_args(argv)
    try:
        is_right = {"left": False, "right": True}.get(args.side) if args.side else side_from_name(args.pickle)
        if is_right is None:
            raise ConvertError(f"cannot tell the hand side from '{args.pickle}'; give --side")
        try:
            tips = [int(t) for t in args.fingertip_verts.split(",")]
        except ValueError as e:
            raise ConvertError(f"--fingertip-verts: expected 5 comma-separated ids: {e}") from e
        raw = load_mano_pickle(args.pickle)
        arrays = convert(raw, args.pickle, is_right, args.fix_left_shapedirs, tips)
        write_npz_atomically(arrays, args.output)
    except ConvertError as e:
        print(f"mano_to_npz: {e}", file=sys.stderr)
        return 1
    side = "right" if is_right else "left"
    print(f"mano_to_npz: wrote {args.output} ({side} hand, {arrays['v_template'].shape[0]} vertices"
          f"{', left shapedirs fixed' if args.fix_left_shapedirs else ''})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
