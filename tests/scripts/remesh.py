#!/usr/bin/env python3
"""Re-meshes bodies as a scanner's software would: a signed distance field sampled on a voxel
grid, its zero level extracted by marching cubes (scikit-image), so that no vertex of the
input survives. Used by tests/pose_symmetry_cases.rs (issue 15: "re-meshed as a scanner
would").

    remesh.py PITCH_MM IN.obj OUT.ply [IN.obj OUT.ply ...]

Near the surface (within BAND_VOXELS) the signed distance of a grid point is its
point-to-plane distance to the nearest of dense surface samples (trimesh), signed by that
sample's face normal: exact to well under a millimetre near a smooth surface, which is all
marching cubes interpolates. Farther points are only outside (connected to the grid's border)
or inside. Only the largest connected piece is kept (gaps narrower than the pitch, between
fingers, close).
"""
import sys

import numpy as np
import trimesh
from scipy.ndimage import binary_dilation, label
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from skimage.measure import marching_cubes

# Surface samples per square millimetre: about 2.2 mm apart, several per voxel face.
SAMPLES_PER_MM2 = 0.2
# Grid margin around the body, in voxels (the zero level must not touch the border).
MARGIN_VOXELS = 3
# Grid points within this many voxels of a sample get a signed distance; marching cubes needs
# it only next to the zero level.
BAND_VOXELS = 2


def remesh(source, target, pitch):
    mesh = trimesh.load(source, process=False, force="mesh")
    count = int(mesh.area * SAMPLES_PER_MM2)
    points, faces = trimesh.sample.sample_surface(mesh, count, seed=0)
    normals = mesh.face_normals[faces]
    lo = mesh.bounds[0] - MARGIN_VOXELS * pitch
    shape = tuple(np.ceil((mesh.bounds[1] - mesh.bounds[0]) / pitch).astype(int) + 2 * MARGIN_VOXELS)
    # The band: voxels holding samples, dilated; only their corners need a distance.
    occupied = np.zeros(shape, dtype=bool)
    occupied[tuple(np.floor((points - lo) / pitch).astype(int).T)] = True
    near = binary_dilation(occupied, iterations=BAND_VOXELS)
    cells = np.argwhere(near)
    grid = lo + pitch * cells
    _, nearest = cKDTree(points).query(grid, workers=-1)
    band = (BAND_VOXELS + 1) * pitch
    sdf = np.full(shape, band)
    sdf[near] = np.einsum("ij,ij->i", grid - points[nearest], normals[nearest])
    # Outside the band: outside when the region reaches the grid's border, inside otherwise.
    labels, _ = label(~near)
    faces_of_grid = [labels[[0, -1]], labels[:, [0, -1]], labels[..., [0, -1]]]
    border = np.unique(np.concatenate([f.ravel() for f in faces_of_grid]))
    sdf[(labels > 0) & ~np.isin(labels, border)] = -band
    verts, tris, _, _ = marching_cubes(sdf, level=0.0, spacing=(pitch,) * 3)
    # The largest connected piece (vertices linked by the triangles' edges).
    n = len(verts)
    edges = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]]])
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, piece = connected_components(graph, directed=False)
    keep = piece[tris[:, 0]] == np.bincount(piece).argmax()
    # marching_cubes's default ("descent") orientation is counter-clockwise seen from the
    # larger values: from outside here. Unused vertices are left for the reader to drop.
    out = trimesh.Trimesh(verts + lo, tris[keep], process=False)
    out.export(target)  # binary PLY


def main():
    pitch = float(sys.argv[1])
    pairs = sys.argv[2:]
    for source, target in zip(pairs[::2], pairs[1::2]):
        remesh(source, target, pitch)


if __name__ == "__main__":
    main()
