#!/usr/bin/env python3
"""Test of tools/arctic_to_sequences.py on a tiny fake ARCTIC tree built here.

The tree has ARCTIC's layout (raw_seqs/<subject>/<seq>.mano.npy as pickled dicts,
<seq>.object.npy [N, 7] with millimetre translations, meta/object_vtemplates/box/ with
closed top.obj/bottom.obj in millimetres). The hand models are bimart's procedural hands
(`bimart hand make`), whose hands_mean is not zero. After the numpy checks, `bimart eval`
reads the converted test split, so bimart really loads the files.

    test_arctic_to_sequences.py --converter tools/arctic_to_sequences.py --bimart build/bin/bimart
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

from tool_checks import check, run  # tests/tools/tool_checks.py

N = 24  # frames per fake sequence


def cube_obj(lo, hi):
    """A closed axis-aligned box as OBJ text, triangles counter-clockwise seen from outside."""
    v = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    # vertex id = 4*ix + 2*iy + iz
    quads = [(0, 1, 3, 2), (4, 6, 7, 5),  # x = lo, x = hi
             (0, 4, 5, 1), (2, 3, 7, 6),  # y = lo, y = hi
             (0, 2, 6, 4), (1, 5, 7, 3)]  # z = lo, z = hi
    lines = ["# fake ARCTIC part, mm"] + [f"v {x} {y} {z}" for x, y, z in v]
    for a, b, c, d in quads:
        lines += [f"f {a + 1} {b + 1} {c + 1}", f"f {a + 1} {c + 1} {d + 1}"]
    return "\n".join(lines) + "\n"


def fake_hand(rng, n, side, shape_rows=False):
    x = -0.12 if side == "left" else 0.12
    return {
        "rot": rng.standard_normal((n, 3)) * 0.3,
        "pose": rng.standard_normal((n, 45)) * 0.1,
        "trans": np.array([x, 0.05, 0.0]) + rng.standard_normal((n, 3)) * 0.01,
        "shape": (np.tile(rng.standard_normal(10) * 0.5, (n, 1)) if shape_rows else rng.standard_normal(10) * 0.5),
        "fitting_err": rng.random(n),
    }


def fake_states(rng, n):
    s = np.zeros((n, 7))
    s[:, 0] = np.linspace(0.0, 0.8, n)                          # hinge angle, rad
    s[:, 1:4] = rng.standard_normal(3) * 0.2                    # root axis-angle
    s[:, 4:7] = np.array([10.0, -20.0, 600.0]) + rng.standard_normal((n, 3)) * 5  # mm
    return s


def write_seq(root, subject, seq, mano, states):
    d = os.path.join(root, "raw_seqs", subject)
    os.makedirs(d, exist_ok=True)
    np.save(os.path.join(d, f"{seq}.mano.npy"), mano, allow_pickle=True)
    np.save(os.path.join(d, f"{seq}.object.npy"), states)


def build_tree(root, rng, objects=("box",)):
    """The good fake tree; returns {sequence name: (mano dict, states)}."""
    for o in objects:
        t = os.path.join(root, "meta", "object_vtemplates", o)
        os.makedirs(t, exist_ok=True)
        with open(os.path.join(t, "bottom.obj"), "w") as f:
            f.write(cube_obj((-100, -80, -60), (100, 0, 60)))
        with open(os.path.join(t, "top.obj"), "w") as f:
            f.write(cube_obj((-100, 0, -60), (100, 15, 60)))
    seqs = {}
    for subject, seq, rows in (("s01", "box_grab_01", False), ("s01", "box_use_02", True),
                               ("s03", "box_use_01", False)):
        mano = {"left": fake_hand(rng, N, "left", rows), "right": fake_hand(rng, N, "right")}
        states = fake_states(rng, N)
        write_seq(root, subject, seq, mano, states)
        seqs[f"{subject}_{seq}"] = (mano, states)
    # Other ARCTIC files beside them are ignored.
    np.save(os.path.join(root, "raw_seqs", "s01", "box_grab_01.egocam.dist.npy"), np.zeros((N, 3)))
    return seqs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--converter", required=True)
    ap.add_argument("--bimart", required=True)
    args = ap.parse_args()
    rng = np.random.default_rng(0)

    with tempfile.TemporaryDirectory() as tmp:
        hands = os.path.join(tmp, "hands")
        run([args.bimart, "hand", "make", "--side", "both", "--out", hands])
        left_model, right_model = os.path.join(hands, "mano_left.npz"), os.path.join(hands, "mano_right.npz")
        mean = {"left": np.load(left_model)["hands_mean"], "right": np.load(right_model)["hands_mean"]}
        check(np.abs(mean["left"]).max() > 0.01 and np.abs(mean["right"]).max() > 0.01,
              "the procedural hands have a non-zero hands_mean")

        def conv(arctic, out, *extra, models=(left_model, right_model)):
            return [sys.executable, args.converter, arctic, out, "--mano-left", models[0],
                    "--mano-right", models[1], *extra]

        arctic = os.path.join(tmp, "arctic")
        seqs = build_tree(arctic, rng)
        out = os.path.join(tmp, "out")
        r = run(conv(arctic, out))
        check("[3/3]" in r.stdout and "3 sequences (train 2, test 1)" in r.stdout,
              "progress and summary printed")

        # Layout and manifest.
        with open(os.path.join(out, "manifest.json")) as f:
            m = json.load(f)
        check({k: m[k] for k in ("format", "version", "generator", "seed", "fps")} ==
              {"format": "bimart-dataset", "version": 1, "generator": "arctic_to_sequences.py", "seed": 0,
               "fps": 30}, "manifest header")
        check(m["train"] == ["sequences/s01_box_grab_01.npz", "sequences/s01_box_use_02.npz"] and
              m["test"] == ["sequences/s03_box_use_01.npz"], "the split follows subjects (s03 = test)")
        check(m["objects"] == [{"name": "box", "path": "objects/box", "category": "box", "split": "train+test"}],
              "manifest objects")
        check(sorted(os.listdir(os.path.join(out, "sequences"))) ==
              ["s01_box_grab_01.npz", "s01_box_use_02.npz", "s03_box_use_01.npz"] and
              sorted(os.listdir(out)) == ["manifest.json", "objects", "sequences"],
              "exactly the documented files, no temporaries")
        for part in ("top.obj", "bottom.obj"):
            with open(os.path.join(out, "objects", "box", part), "rb") as a, \
                    open(os.path.join(arctic, "meta", "object_vtemplates", "box", part), "rb") as b:
                check(a.read() == b.read(), f"objects/box/{part} copied unchanged (mm)")

        # Sequence contents.
        for name, (mano, states) in seqs.items():
            z = np.load(os.path.join(out, "sequences", name + ".npz"))
            expect = {"format_version": ((), np.int64), "name": ((), None), "object": ((), None),
                      "category": ((), None), "kind": ((), None), "fps": ((), np.float64),
                      "object_states": ((N, 7), np.float32)}
            for h in ("left", "right"):
                expect.update({f"{h}_rot": ((N, 3), np.float32), f"{h}_pose": ((N, 45), np.float32),
                               f"{h}_trans": ((N, 3), np.float32), f"{h}_shape": ((10,), np.float32)})
            check(set(z.files) == set(expect) and
                  all(z[k].shape == s and (t is None or z[k].dtype == t) for k, (s, t) in expect.items()) and
                  all(z[k].dtype.kind == "U" for k in ("name", "object", "category", "kind")),
                  f"{name}: keys, shapes and dtypes")
            subject, seq = name.split("_", 1)
            check(int(z["format_version"]) == 1 and str(z["name"]) == name and
                  str(z["object"]) == "../objects/box" and str(z["category"]) == "box" and
                  str(z["kind"]) == seq.split("_")[1] and float(z["fps"]) == 30.0,
                  f"{name}: format_version, name, object, category, kind, fps")
            for h in ("left", "right"):
                src = mano[h]
                check(np.array_equal(z[f"{h}_pose"], (src["pose"] + mean[h]).astype(np.float32)) and
                      not np.allclose(z[f"{h}_pose"], src["pose"], atol=1e-3),
                      f"{name}: {h} pose = ARCTIC pose + hands_mean of the {h} model")
                check(np.array_equal(z[f"{h}_rot"], src["rot"].astype(np.float32)) and
                      np.array_equal(z[f"{h}_trans"], src["trans"].astype(np.float32)),
                      f"{name}: {h} rot and trans (m) unchanged")
                want_shape = src["shape"].mean(0) if src["shape"].ndim == 2 else src["shape"]
                check(np.allclose(z[f"{h}_shape"], want_shape, atol=1e-6), f"{name}: {h} shape [10]")
            st = z["object_states"]
            check(np.array_equal(st[:, :4], states[:, :4].astype(np.float32)) and
                  np.allclose(st[:, 4:], states[:, 4:] / 1000, atol=1e-7) and 0.5 < st[0, 6] < 0.7,
                  f"{name}: object angle and rotation unchanged, translation mm -> m")

        # bimart reads the data set.
        j = os.path.join(tmp, "eval.json")
        run([args.bimart, "eval", "--ground-truth", out, "--split", "test", "--json", j, "--quiet",
             "--threads", "2"])
        with open(j) as f:
            ev = json.load(f)
        gt = ev["ground_truth"]
        files = sorted(os.path.relpath(p["file"], out) for p in gt["per_sequence"])
        check(gt["sequences"] == 1 and files == m["test"] and
              [p["name"] for p in gt["per_sequence"]] == ["s03_box_use_01"] and
              gt["per_sequence"][0]["frames"] == N,
              "bimart eval --ground-truth OUT --split test reads the test sequences")

        # Refusals: exit code 2, a message naming the file, no traceback, nothing written.
        def refused(cmd, needles, what, out_dir):
            r = run(cmd, expect_rc=2)
            ok = all(n in r.stderr for n in needles) and "Traceback" not in r.stderr
            check(ok and not os.path.exists(os.path.join(out_dir, "manifest.json")), what)
            return r

        def bad_tree(tag, edit):
            root = os.path.join(tmp, "bad_" + tag)
            mano = {"left": fake_hand(rng, N, "left"), "right": fake_hand(rng, N, "right")}
            states = fake_states(rng, N)
            build_tree(root, rng)
            seq = edit(mano, states)
            write_seq(root, "s02", seq, mano, states)
            return root, os.path.join("raw_seqs", "s02", seq)

        bad_out = os.path.join(tmp, "bad_out")
        refused(conv(os.path.join(tmp, "nowhere"), bad_out), ["nowhere", "no such folder"],
                "a missing ARCTIC folder is refused", bad_out)
        no_meta = os.path.join(tmp, "no_meta")
        shutil.copytree(os.path.join(arctic, "raw_seqs"), os.path.join(no_meta, "raw_seqs"))
        refused(conv(no_meta, bad_out), [os.path.join("meta", "object_vtemplates"), "no such folder"],
                "a missing templates folder is refused", bad_out)

        def one_hand(mano, states):
            del mano["right"]
            return "box_grab_05"
        root, f = bad_tree("hand", one_hand)
        refused(conv(root, bad_out), [f + ".mano.npy", "'right'", "both hands"],
                "a .mano.npy without both hands is refused", bad_out)

        def short(mano, states):
            mano["left"] = fake_hand(rng, N - 3, "left")
            mano["right"] = fake_hand(rng, N - 3, "right")
            return "box_use_06"
        root, f = bad_tree("frames", short)
        refused(conv(root, bad_out), [f + ".mano.npy", f + ".object.npy", "frame counts disagree"],
                "mano and object frame counts that disagree are refused", bad_out)

        def nan(mano, states):
            mano["left"]["pose"][5, 7] = np.nan
            return "box_use_07"
        root, f = bad_tree("nan", nan)
        refused(conv(root, bad_out), [f + ".mano.npy", "'left' 'pose'", "not finite"],
                "a non-finite hand value is refused", bad_out)

        def inf_obj(mano, states):
            states[3, 5] = np.inf
            return "box_use_08"
        root, f = bad_tree("inf", inf_obj)
        refused(conv(root, bad_out), [f + ".object.npy", "not finite"],
                "a non-finite object state is refused", bad_out)

        def kettle(mano, states):
            return "kettle_use_01"
        root, f = bad_tree("object", kettle)
        refused(conv(root, bad_out), [f + ".mano.npy", "unknown object 'kettle'",
                                      os.path.join("object_vtemplates", "kettle", "top.obj")],
                "an unknown object template is refused", bad_out)
        check(not os.path.exists(bad_out), "a refused conversion writes nothing")

        refused(conv(arctic, bad_out, models=(right_model, left_model)), [right_model, "--mano-left"],
                "swapped hand models are refused", bad_out)
        foreign = os.path.join(tmp, "foreign")
        os.makedirs(foreign)
        open(os.path.join(foreign, "notes.txt"), "w").close()
        refused(conv(arctic, foreign), [foreign, "not empty"], "a foreign non-empty output folder is refused",
                foreign)

        # Rerun into the earlier output with filters: stale sequences of that run go.
        run(conv(arctic, out, "--subjects", "s03", "--objects", "box"))
        with open(os.path.join(out, "manifest.json")) as f:
            m2 = json.load(f)
        check(m2["train"] == [] and m2["test"] == ["sequences/s03_box_use_01.npz"] and
              m2["objects"][0]["split"] == "test" and
              os.listdir(os.path.join(out, "sequences")) == ["s03_box_use_01.npz"],
              "a rerun with --subjects replaces the earlier output, stale sequences removed")
        r = run(conv(arctic, out, "--test-subjects", "s01,s03"))
        check("train split is empty" in r.stderr, "a warning when every sequence is a test subject's")
    print("all checks passed")


if __name__ == "__main__":
    main()
