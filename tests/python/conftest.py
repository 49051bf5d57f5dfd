"""Shared fixtures: the module, the bvhlab CLI to compare against, and meshes whose geometry is known."""
import json
import os
import subprocess

import numpy as np
import pytest

import bvhlab


def box_mesh(center=(0.0, 0.0, 0.0), half=(0.5, 0.5, 0.5), name="box"):
    """An axis-aligned box: 8 vertices, 12 triangles."""
    c, h = np.asarray(center, float), np.asarray(half, float)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return bvhlab.Mesh(c + corners * h, np.array(faces, dtype=np.int32), name)


def rotation_z(degrees):
    a = np.radians(degrees)
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


def matrix(rotation, translation):
    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = translation
    return m


@pytest.fixture(scope="session")
def cli():
    """Runs the bvhlab CLI; with json=True, parses what it prints."""
    path = os.environ.get("BVHLAB_CLI")
    assert path and os.path.isfile(path), "BVHLAB_CLI must name the bvhlab executable (ctest sets it)"

    def run(*args, parse_json=True):
        out = subprocess.run([path, *map(str, args)], check=True, capture_output=True, text=True).stdout
        return json.loads(out) if parse_json else out

    return run


@pytest.fixture(scope="session")
def source_dir():
    path = os.environ.get("BVHLAB_SOURCE_DIR")
    assert path and os.path.isdir(path), "BVHLAB_SOURCE_DIR must name the source tree (ctest sets it)"
    return path


@pytest.fixture(scope="session")
def gear_file(tmp_path_factory):
    """The bundled gear normalised, on a grid of 1/1024 (exact in the loader's 32-bit floats), with two small
    triangles at the corners of [-1, 1]^3: the protocol normalisation leaves this file's coordinates as they
    are, so the CLI reads the same mesh whether or not it normalises."""
    gear = bvhlab.load_mesh("pinion.off", normalize=True)
    vertices = np.round(gear.vertices * 1024) / 1024
    corners = np.array([[-1, -1, -1], [-1 + 1 / 64, -1, -1], [-1, -1 + 1 / 64, -1],
                        [1, 1, 1], [1 - 1 / 64, 1, 1], [1, 1 - 1 / 64, 1]])
    vertices = np.concatenate([vertices, corners])
    n = len(gear.vertices)
    triangles = np.concatenate([gear.triangles, [[n, n + 1, n + 2], [n + 3, n + 4, n + 5]]])
    path = tmp_path_factory.mktemp("meshes") / "gear.off"
    with open(path, "w") as f:
        f.write(f"OFF\n{len(vertices)} {len(triangles)} 0\n")
        f.writelines(f"{x:.10f} {y:.10f} {z:.10f}\n" for x, y, z in vertices)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in triangles)
    return path


@pytest.fixture(scope="session")
def gear(gear_file):
    mesh = bvhlab.load_mesh(gear_file)
    np.testing.assert_array_equal(mesh.vertices, bvhlab.load_mesh(gear_file, normalize=True).vertices)
    return mesh
