#!/usr/bin/env python3
"""Writes the binary seed inputs of tests/fuzz/corpus/ (numpy only). The YAML seeds are
copies of pipelines/*.yaml plus flow.yaml. Run from tests/fuzz/: python3 make_corpus.py"""
import io
import struct

import numpy as np

c = 'corpus/'
tet_v = [(0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)]
tet_f = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]

# Meshes: the first byte picks the format (fuzz_mesh.cc): 0 obj, 1 off, 2 ply, 3 stl.
obj = ''.join(f'v {x} {y} {z}\n' for x, y, z in tet_v) + ''.join(f'f {a+1} {b+1} {d+1}\n' for a, b, d in tet_f)
open(c + 'mesh/tetra.obj.bin', 'wb').write(b'\x00' + obj.encode())
off = 'OFF\n4 4 0\n' + ''.join(f'{x} {y} {z}\n' for x, y, z in tet_v) + ''.join(f'3 {a} {b} {d}\n' for a, b, d in tet_f)
open(c + 'mesh/tetra.off.bin', 'wb').write(b'\x01' + off.encode())
ply = ('ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n'
       'element face 4\nproperty list uchar int vertex_indices\nend_header\n'
       + ''.join(f'{x} {y} {z}\n' for x, y, z in tet_v) + ''.join(f'3 {a} {b} {d}\n' for a, b, d in tet_f))
open(c + 'mesh/tetra.ply.bin', 'wb').write(b'\x02' + ply.encode())
for order, fmt in (('little', '<'), ('big', '>')):  # binary PLY with extra properties (core/object/ply_file.cc)
    head = (f'ply\nformat binary_{order}_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n'
            'property float z\nproperty uchar flag\nelement face 4\nproperty uchar red\n'
            'property list uchar int vertex_indices\nend_header\n').encode()
    body = b''.join(struct.pack(fmt + '3fB', *v, 7) for v in tet_v)
    body += b''.join(struct.pack(fmt + 'BB3i', 0, 3, *f) for f in tet_f)
    open(c + f'mesh/tetra_{order}.ply.bin', 'wb').write(b'\x02' + head + body)
stl = bytearray(b'bimart fuzz seed'.ljust(80, b' ')) + struct.pack('<I', 4)
for f in tet_f:
    stl += struct.pack('<3f', 0, 0, 0)
    for i in f:
        stl += struct.pack('<3f', *tet_v[i])
    stl += b'\0\0'
open(c + 'mesh/tetra.stl.bin', 'wb').write(b'\x03' + bytes(stl))
open(c + 'mesh/quads.obj.bin', 'wb').write(
    b'\x00# cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvn 0 0 1\n'
    b'f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n')

# A two-frame sequence (docs/formats.md), stored and deflated; two .npy arrays.
n = 2
seq = dict(format_version=np.int64(1), name=np.array('fuzz'), object=np.array('../objects/box'),
           category=np.array('box'), kind=np.array('grab'), fps=np.float64(30),
           object_states=np.zeros((n, 7), np.float32))
for side in ('left', 'right'):
    seq[side + '_rot'] = np.zeros((n, 3), np.float32)
    seq[side + '_pose'] = np.zeros((n, 45), np.float32)
    seq[side + '_trans'] = np.full((n, 3), 0.3, np.float32)
    seq[side + '_shape'] = np.zeros(10, np.float32)
np.savez(c + 'sequence/two_frames.npz', **seq)
np.savez_compressed(c + 'sequence/two_frames_deflate.npz', **seq)
for name, a in (('matrix.npy', np.arange(6, dtype='<f8').reshape(2, 3)), ('strings.npy', np.array(['a', 'bc']))):
    buf = io.BytesIO()
    np.save(buf, a)
    open(c + 'sequence/' + name, 'wb').write(buf.getvalue())

# A tiny hand model in MANO layout, V = 8 (docs/formats.md, "Hand model").
rng = np.random.default_rng(3)
V = 8
w = np.zeros((V, 16))
w[np.arange(V), np.arange(V) % 16] = 1
J = np.zeros((16, V))
J[np.arange(16), np.arange(16) % V] = 1
hm = dict(v_template=rng.uniform(-.05, .05, (V, 3)).astype(np.float32),
          shapedirs=(rng.uniform(-1, 1, (V, 3, 10)) * 0.01).astype(np.float32),
          posedirs=(rng.uniform(-1, 1, (V, 3, 135)) * 0.005).astype(np.float32),
          J_regressor=J.astype(np.float32), weights=w.astype(np.float32),
          kintree_table=np.array([[-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14], list(range(16))], np.int64),
          f=np.array([[0, 1, 2], [2, 3, 4], [4, 5, 6], [6, 7, 0]], np.int32),
          hands_components=np.eye(45, dtype=np.float32), hands_mean=np.zeros(45, np.float32),
          fingertip_verts=np.array([0, 1, 2, 3, 4], np.int64), keypoint_verts=np.arange(V, dtype=np.int64),
          is_right=np.bool_(True))
np.savez_compressed(c + 'hand_model/tiny_right.npz', **hm)
left = dict(hm)
del left['keypoint_verts']
left['is_right'] = np.bool_(False)
np.savez(c + 'hand_model/tiny_left_stored.npz', **left)

# BPS bases: 16 points in the unit ball and in a 0.5 m ball.
p = rng.normal(size=(16, 3))
p /= np.linalg.norm(p, axis=1, keepdims=True)
p *= rng.uniform(0, 1, (16, 1)) ** (1 / 3)
np.savez_compressed(c + 'bps_basis/basis16.npz', points=p, radius=np.float64(1.0), seed=np.uint64(0))
np.savez(c + 'bps_basis/basis16_half.npz', points=p * 0.5, radius=np.float64(0.5), seed=np.uint64(9))
