"""Helpers for the lab 04 pictures: read the OBJ frames `lab04_pbd --frames N`
writes and draw one with a fixed orthographic camera (no physics here)."""
import re
from pathlib import Path

import numpy as np

LAB = "lab04_pbd"
HEADER = re.compile(r"#.*scene (\S+) frame (\d+) time (\S+)")


class Frame:
    """One OBJ frame: vertices (n x 3), triangles (m x 3, 0-based) or lines (k x 2)."""

    def __init__(self, path):
        self.path = Path(path)
        self.scene, self.frame, self.time = "?", 0, 0.0
        vertices, faces, lines = [], [], []
        with open(path, encoding="utf-8") as handle:
            for line in handle:
                if line.startswith("v "):
                    vertices.append([float(value) for value in line.split()[1:4]])
                elif line.startswith("f "):
                    faces.append([int(value.split("/")[0]) - 1 for value in line.split()[1:4]])
                elif line.startswith("l "):
                    lines.append([int(value) - 1 for value in line.split()[1:3]])
                elif line.startswith("#"):
                    match = HEADER.match(line)
                    if match:
                        self.scene, self.frame, self.time = match[1], int(match[2]), float(match[3])
        self.vertices = np.array(vertices, dtype=float).reshape(-1, 3)
        self.faces = np.array(faces, dtype=int).reshape(-1, 3)
        self.lines = np.array(lines, dtype=int).reshape(-1, 2)


def frame_dirs(out_dir):
    """Run directories OUT/lab04_pbd/<run>/ that hold OBJ frames, sorted."""
    root = Path(out_dir) / LAB
    return sorted(p.parent for p in root.glob("*/frames") if any(p.glob("frame_*.obj")))


def frame_paths(run_dir):
    return sorted((Path(run_dir) / "frames").glob("frame_*.obj"))


def pick(items, count):
    """`count` items evenly spread over `items`, first and last included."""
    if len(items) <= count:
        return list(items)
    index = np.linspace(0, len(items) - 1, count).round().astype(int)
    return [items[i] for i in sorted(set(index))]


# An orthographic camera: turn about the vertical (y) axis, then tilt down.
AZIMUTH, ELEVATION = np.radians(35.0), np.radians(20.0)
_turn = np.array([[np.cos(AZIMUTH), 0, -np.sin(AZIMUTH)], [0, 1, 0], [np.sin(AZIMUTH), 0, np.cos(AZIMUTH)]])
_tilt = np.array([[1, 0, 0], [0, np.cos(ELEVATION), -np.sin(ELEVATION)],
                  [0, np.sin(ELEVATION), np.cos(ELEVATION)]])
CAMERA = _tilt @ _turn  # rows: screen right, screen up, towards the viewer
LIGHT = np.array([0.25, 0.45, 0.85]) / np.linalg.norm([0.25, 0.45, 0.85])  # in camera space


def screen(points):
    """n x 3 world points -> n x 3 camera points (u right, v up, depth towards the viewer)."""
    return points @ CAMERA.T


def edges_of(frame):
    if len(frame.faces):
        e = np.concatenate([frame.faces[:, [0, 1]], frame.faces[:, [1, 2]], frame.faces[:, [2, 0]]])
        return e
    return frame.lines


def stretch(frame, rest):
    """|l / l0 - 1| per edge, l0 from the `rest` frame (the scene's first)."""
    e = edges_of(frame)
    length = np.linalg.norm(frame.vertices[e[:, 0]] - frame.vertices[e[:, 1]], axis=1)
    rest_length = np.linalg.norm(rest.vertices[e[:, 0]] - rest.vertices[e[:, 1]], axis=1)
    return np.abs(length / np.where(rest_length > 0, rest_length, 1.0) - 1.0)


STRETCH_RANGE = (1e-3, 3.0)  # the colour scale of edge stretch, log
CMAP = "YlOrRd"


def draw(axes, frame, rest, limits):
    """Draw `frame` into `axes`, coloured by stretch against `rest`; return the mappable."""
    import matplotlib.cm as cm
    from matplotlib import colors
    from matplotlib.collections import LineCollection, PolyCollection

    mapper = cm.ScalarMappable(norm=colors.LogNorm(*STRETCH_RANGE), cmap=CMAP)
    p = screen(frame.vertices)
    per_edge = np.clip(stretch(frame, rest), STRETCH_RANGE[0], None)
    if len(frame.faces):
        m = len(frame.faces)
        per_face = per_edge.reshape(3, m).max(axis=0)
        tri = p[frame.faces]  # m x 3 x 3
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
        shade = 0.55 + 0.45 * np.abs(normal @ LIGHT)
        rgba = mapper.to_rgba(per_face)
        rgba[:, :3] *= shade[:, None]
        order = np.argsort(tri[:, :, 2].mean(axis=1))  # far (small depth) first
        axes.add_collection(PolyCollection(tri[order, :, :2], facecolors=rgba[order], edgecolors="none",
                                           antialiaseds=False))
    else:
        segments = p[frame.lines][:, :, :2]
        axes.add_collection(LineCollection(segments, colors=mapper.to_rgba(per_edge), linewidths=2.5))
        axes.plot(p[:, 0], p[:, 1], "o", ms=2, color="0.2")
    axes.set_xlim(limits[0])
    axes.set_ylim(limits[1])
    axes.set_aspect("equal")
    axes.set_xticks([])
    axes.set_yticks([])
    return mapper


def limits_of(frames, margin=0.05):
    """Screen-space axis limits that hold every frame."""
    points = np.concatenate([screen(f.vertices) for f in frames])
    low, high = points[:, :2].min(axis=0), points[:, :2].max(axis=0)
    pad = margin * (high - low).max()
    return [(low[0] - pad, high[0] + pad), (low[1] - pad, high[1] + pad)]
