#!/usr/bin/env python3
"""Test of tools/mano_to_npz.py on a fake MANO pickle built here.

The fake has the official key names, chumpy arrays as instances of a class named exactly
chumpy.ch.Ch, and J_regressor as a scipy.sparse.csc.csc_matrix (both fake modules, put on
sys.path only while writing), pickled with protocol 2. The converter must read it with
numpy alone. Last, hand_tests (C++) loads the converted file and compares it with the
expected arrays, saved here by numpy as a stored (uncompressed) .npz.

    test_mano_to_npz.py --converter tools/mano_to_npz.py --hand-tests build/bin/hand_tests
"""

import argparse
import os
import subprocess
import sys
import tempfile
import textwrap

import numpy as np

from tool_checks import check, run  # tests/tools/tool_checks.py

V, F = 20, 30
PARENTS = [-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14]
TIPS = [1, 5, 9, 13, 17]

FAKE_CHUMPY = textwrap.dedent("""
    class Ch(object):
        # chumpy drops its caches and keeps the array as 'x' in the pickled __dict__
        def __init__(self, x):
            self.x = x
            self._dirty_vars = set()
            self._itr = None
        def __getstate__(self):
            return dict(self.__dict__)
""")
FAKE_CSC = textwrap.dedent("""
    class csc_matrix(object):
        def __init__(self, data, indices, indptr, shape):
            self.data, self.indices, self.indptr = data, indices, indptr
            self._shape = shape
            self.maxprint = 50
            self.format = 'csc'
""")
WRITER = textwrap.dedent("""
    import pickle, sys
    import numpy as np
    from chumpy.ch import Ch
    from scipy.sparse.csc import csc_matrix
    d = dict(np.load(sys.argv[1]))
    J = d['J_regressor']
    rows, cols = J.shape
    data, indices, indptr = [], [], [0]
    for c in range(cols):
        nz = np.nonzero(J[:, c])[0]
        data += list(J[nz, c]); indices += list(nz); indptr.append(len(data))
    model = {
        'v_template': Ch(d['v_template']),
        'shapedirs': Ch(d['shapedirs']),
        'posedirs': d['posedirs'],
        'J_regressor': csc_matrix(np.array(data), np.array(indices, dtype=np.int32),
                                  np.array(indptr, dtype=np.int32), (rows, cols)),
        'weights': Ch(d['weights']),
        'kintree_table': d['kintree_table'],
        'f': d['f'],
        'hands_components': d['hands_components'],
        'hands_mean': d['hands_mean'],
        'hands_coeffs': np.zeros((10, 45)),
        'J': np.zeros((16, 3)),
        'bs_style': 'lbs',
        'bs_type': 'lrotmin',
    }
    with open(sys.argv[2], 'wb') as f:
        pickle.dump(model, f, protocol=2)
""")


def random_model(rng):
    weights = rng.random((V, 16)) * (rng.random((V, 16)) < 0.3) + 1e-3
    weights /= weights.sum(1, keepdims=True)
    J = np.zeros((16, V))
    for j in range(16):
        J[j, rng.choice(V, 3, replace=False)] = 1.0 / 3
    tree = np.array([[4294967295] + PARENTS[1:], list(range(16))], dtype=np.int64)
    return {
        "v_template": rng.standard_normal((V, 3)) * 0.05,
        "shapedirs": rng.standard_normal((V, 3, 10)) * 0.01,
        "posedirs": rng.standard_normal((V, 3, 135)) * 0.01,
        "J_regressor": J,
        "weights": weights,
        "kintree_table": tree,
        "f": rng.integers(0, V, (F, 3)).astype(np.uint32),
        "hands_components": np.linalg.qr(rng.standard_normal((45, 45)))[0],
        "hands_mean": rng.standard_normal(45) * 0.2,
    }


def write_fake_pickle(tmp, arrays, path):
    fake = os.path.join(tmp, "fake_modules")
    for pkg in ("chumpy", "scipy", os.path.join("scipy", "sparse")):
        os.makedirs(os.path.join(fake, pkg), exist_ok=True)
        open(os.path.join(fake, pkg, "__init__.py"), "w").close()
    with open(os.path.join(fake, "chumpy", "ch.py"), "w") as f:
        f.write(FAKE_CHUMPY)
    with open(os.path.join(fake, "scipy", "sparse", "csc.py"), "w") as f:
        f.write(FAKE_CSC)
    src = os.path.join(tmp, "source.npz")
    np.savez(src, **arrays)
    env = dict(os.environ, PYTHONPATH=fake)
    subprocess.run([sys.executable, "-c", WRITER, src, path], env=env, check=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--converter", required=True)
    ap.add_argument("--hand-tests", required=True)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    src = random_model(rng)
    conv = [sys.executable, args.converter]
    tips = ["--fingertip-verts", ",".join(map(str, TIPS))]

    with tempfile.TemporaryDirectory() as tmp:
        right_pkl = os.path.join(tmp, "MANO_RIGHT.pkl")
        left_pkl = os.path.join(tmp, "MANO_LEFT.pkl")
        write_fake_pickle(tmp, src, right_pkl)
        write_fake_pickle(tmp, src, left_pkl)
        with open(right_pkl, "rb") as f:
            raw = f.read()
        check(raw[:2] == b"\x80\x02" and b"chumpy.ch\nCh" in raw and b"scipy.sparse.csc\ncsc_matrix" in raw,
              "the fake pickle is protocol 2 and names chumpy.ch.Ch and scipy.sparse.csc.csc_matrix")

        right = os.path.join(tmp, "right.npz")
        r = run(conv + [right_pkl, right], expect_rc=None)
        check("fingertip vertex ids" in r.stderr and "below 20" in r.stderr,
              "MANO's fingertip ids are refused on a 20-vertex mesh, with a clear message")
        run(conv + [right_pkl, right] + tips)
        out = np.load(right)
        check(set(out.files) == {"v_template", "shapedirs", "posedirs", "J_regressor", "weights",
                                 "kintree_table", "f", "hands_components", "hands_mean",
                                 "fingertip_verts", "is_right"}, "the documented keys")
        for key in ("v_template", "shapedirs", "posedirs", "weights", "hands_components", "hands_mean"):
            check(np.array_equal(out[key], src[key]) and out[key].dtype == np.float64, f"{key} equal, float64")
        check(np.array_equal(out["J_regressor"], src["J_regressor"]), "sparse J_regressor densified exactly")
        check(out["kintree_table"][0, 0] == -1 and list(out["kintree_table"][0, 1:]) == PARENTS[1:],
              "root parent uint32 max becomes -1")
        check(np.array_equal(out["f"], src["f"]) and out["f"].dtype == np.int32, "faces as int32")
        check(list(out["fingertip_verts"]) == TIPS, "fingertip ids as given")
        check(out["is_right"].shape == () and bool(out["is_right"]), "is_right True from the file name")

        left = os.path.join(tmp, "left.npz")
        left_fixed = os.path.join(tmp, "left_fixed.npz")
        run(conv + [left_pkl, left] + tips)
        run(conv + [left_pkl, left_fixed, "--fix-left-shapedirs"] + tips)
        a, b = np.load(left), np.load(left_fixed)
        check(not bool(a["is_right"]), "is_right False for MANO_LEFT")
        check(np.array_equal(a["shapedirs"], src["shapedirs"]), "left shapedirs unchanged by default")
        check(np.array_equal(b["shapedirs"][:, 0, :], -src["shapedirs"][:, 0, :]) and
              np.array_equal(b["shapedirs"][:, 1:, :], src["shapedirs"][:, 1:, :]),
              "--fix-left-shapedirs negates shapedirs[:, 0, :] only")
        r = run(conv + [right_pkl, os.path.join(tmp, "x.npz"), "--fix-left-shapedirs"] + tips, expect_rc=None)
        check("left hand only" in r.stderr, "--fix-left-shapedirs refused for the right hand")
        r = run(conv + [os.path.join(tmp, "hand.pkl"), os.path.join(tmp, "x.npz")], expect_rc=None)
        check("give --side" in r.stderr, "a file name without LEFT/RIGHT needs --side")
        with open(os.path.join(tmp, "MANO_RIGHT_broken.pkl"), "wb") as f:
            f.write(b"not a pickle")
        r = run(conv + [os.path.join(tmp, "MANO_RIGHT_broken.pkl"), os.path.join(tmp, "x.npz")],
                expect_rc=None)
        check("not a readable MANO pickle" in r.stderr, "a broken pickle is reported")
        check(not os.path.exists(os.path.join(tmp, "x.npz")), "no output after a failure")

        # The C++ loader reads the converted files (deflated, by numpy) and agrees with
        # numpy's values (stored members).
        for model_path, is_right in ((right, True), (left_fixed, False)):
            m = np.load(model_path)
            expected = os.path.join(tmp, "expected.npz")
            np.savez(expected, v_template=m["v_template"], shapedirs=m["shapedirs"],
                     posedirs=m["posedirs"], J_regressor_dense=src["J_regressor"],
                     weights=m["weights"], hands_components=m["hands_components"],
                     hands_mean=m["hands_mean"], parents=np.array(PARENTS, dtype=np.int64),
                     f=m["f"], fingertip_verts=m["fingertip_verts"], is_right=np.array(is_right))
            resaved = os.path.join(tmp, "resaved.npz")
            env = dict(os.environ, BIMART_TEST_MANO_NPZ=model_path, BIMART_TEST_MANO_EXPECTED=expected,
                       BIMART_TEST_MANO_RESAVED=resaved)
            r = run([args.hand_tests, "--gtest_filter=ManoConvertedFile.*", "--gtest_color=no"], env=env)
            check("[  PASSED  ] 1 test" in r.stdout and "SKIPPED" not in r.stdout,
                  f"hand_tests loads {os.path.basename(model_path)} with numpy's values")
            # ...and numpy reads what bimart saves.
            back = np.load(resaved)
            same = all(np.array_equal(back[k], m[k]) for k in m.files)
            check(same and back["is_right"].dtype == np.bool_ and back["f"].dtype == np.int32,
                  f"numpy reads bimart's save of {os.path.basename(model_path)} unchanged")
    print("all checks passed")


if __name__ == "__main__":
    main()
