"""Views as pictures through matplotlib: a PNG of one frame, a GIF of a stretch of frames.

The picture is the HTML view's (:mod:`.page`) without interaction, in the same colours
(:mod:`.style`): the top-down map (lanes, intersections, crosswalks) or the camera images, one
panel per camera channel named above it (the page shows one channel at a time and switches),
the objects as oriented boxes coloured by kind (an image box of no object by its class's
kind), the corresponded objects filled in their program name's colour, labelled with the name
and their path over the window drawn, and below a time line with the behaviour labels of the
corresponded objects (or the number of objects per frame), the match window shaded.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np

from ..errors import UserError
from ..model.geometry import box_corners
from ..wording import numbered
from .data import MatchView, TraceView, image_channels
from .style import (
    MARKED_COLOUR,
    SCENE_COLOURS,
    behaviour_colours,
    category_colours,
    class_colours,
    program_colours,
)

MIN_SIZE = 0.5
"""Boxes are drawn at least this long and wide (metres), so that points and unknown sizes show."""

GIF_MAX_FRAMES = 150
"""A GIF shows at most this many frames (every k-th frame of a longer stretch)."""

GIF_MARGIN = 10
"""Frames shown before and after a match window in a GIF."""


@dataclass(frozen=True)
class Boxes:
    """The boxes of one view in a form matplotlib takes: per row its frame, object (-1 none),
    corners (n, 4, 2), centre (n, 2), whether the query's classes mark it, its panel (the
    position of its camera channel in ``panels``; 0 top-down) and its kind's colour (an
    image box of no object: its class's), in frame order."""

    frame: np.ndarray
    object: np.ndarray
    corners: np.ndarray
    centre: np.ndarray
    marked: np.ndarray
    panel: np.ndarray
    colour: np.ndarray
    panels: tuple[str, ...]

    @classmethod
    def of(cls, view: TraceView) -> Boxes:
        if view.image_space:
            return cls._image(view)
        st = view.trace.states
        length = np.maximum(np.nan_to_num(st.length, nan=MIN_SIZE), MIN_SIZE)
        width = np.maximum(np.nan_to_num(st.width, nan=MIN_SIZE), MIN_SIZE)
        corners = box_corners(st.x, st.y, st.heading, length, width)
        marked = np.zeros(len(st), bool) if view.marked is None else view.marked
        colour = np.array(_kind_colours(view) or [""], dtype=object)[st.object]
        centre = np.stack([st.x, st.y], axis=1)
        return cls(st.frame, st.object, corners, centre, marked, np.zeros(len(st), np.int64), colour, ("",))

    @classmethod
    def _image(cls, view: TraceView) -> Boxes:
        assert view.trace.images is not None
        samples, boxes = view.trace.images.samples, view.trace.images.boxes
        panels = image_channels(view)
        panel_of = np.full(len(samples.channels), -1, np.int64)
        panel_of[[samples.channels.index(c) for c in panels]] = np.arange(len(panels))
        c, s = np.cos(boxes.rotation)[:, None], np.sin(boxes.rotation)[:, None]
        u = np.array([-1, 1, 1, -1])[None, :] * boxes.w[:, None] / 2
        v = np.array([-1, -1, 1, 1])[None, :] * boxes.h[:, None] / 2
        corners = np.stack([boxes.cx[:, None] + u * c - v * s, boxes.cy[:, None] + u * s + v * c], axis=2)
        marked = np.zeros(len(boxes), bool) if view.marked_boxes is None else view.marked_boxes
        by_class = np.array(category_colours(boxes.classes) or [""], dtype=object)[boxes.category]
        by_object = np.array(_kind_colours(view) or [""], dtype=object)[np.maximum(boxes.object, 0)]
        colour = np.where(boxes.object >= 0, by_object, by_class)
        frame = samples.frame[boxes.sample]
        order = np.argsort(frame, kind="stable")
        centre = np.stack([boxes.cx, boxes.cy], axis=1)
        panel = panel_of[samples.channel[boxes.sample]]
        columns = (frame, boxes.object, corners, centre, marked, panel, colour)
        return cls(*(column[order] for column in columns), panels)


def picture(view: TraceView, kind: str, match: MatchView | None = None, frame: int | None = None) -> bytes:
    """The bytes of a ``kind`` 'png' picture of one frame (``frame``, a position; default the
    window's first frame) or a 'gif' of the match window with :data:`GIF_MARGIN` frames around it
    (the whole trace without a match)."""
    import matplotlib

    matplotlib.use("Agg")
    figure = Figure(view, match)
    try:
        if kind == "png":
            figure.show_frame(_frame(view, match, frame))
            buffer = io.BytesIO()
            figure.figure.savefig(buffer, format="png", dpi=100)
            return buffer.getvalue()
        return figure.gif(_gif_frames(view, match))
    finally:
        figure.close()


def _frame(view: TraceView, match: MatchView | None, frame: int | None) -> int:
    if frame is None:
        return match.first if match is not None else 0
    if not 0 <= frame < view.trace.n_frames:
        raise UserError(f"--frame {frame}: the trace has {numbered(view.trace.n_frames, 'frame')}")
    return frame


def _gif_frames(view: TraceView, match: MatchView | None) -> np.ndarray:
    first, last = (0, view.trace.n_frames - 1) if match is None else (match.first, match.last)
    first, last = max(first - GIF_MARGIN, 0), min(last + GIF_MARGIN, view.trace.n_frames - 1)
    step = max(1, -(-(last - first + 1) // GIF_MAX_FRAMES))
    return np.arange(first, last + 1, step)


class Figure:
    """A matplotlib figure of a view whose boxes are redrawn per frame (see the module docstring):
    one panel (axes) per camera channel of an image view, one top-down panel otherwise."""

    def __init__(self, view: TraceView, match: MatchView | None):
        import matplotlib.pyplot as plt

        self.view, self.match = view, match
        self.boxes = Boxes.of(view)
        self.offsets = np.searchsorted(self.boxes.frame, np.arange(view.trace.n_frames + 1))
        self.names = _names(view, match)
        self.colours = program_colours([n for m in view.matches for n in m.correspondence])
        self.figure = plt.figure(figsize=(10, 7.5), layout="constrained")
        n = len(self.boxes.panels)
        columns = int(np.ceil(np.sqrt(n)))
        rows = -(-n // columns)
        grid = self.figure.add_gridspec(rows + 1, columns, height_ratios=(*[6 / rows] * rows, 1))
        self.axes = [self.figure.add_subplot(grid[k // columns, k % columns]) for k in range(n)]
        self.timeline = self.figure.add_subplot(grid[rows, :])
        self._draw_static()

    def close(self) -> None:
        import matplotlib.pyplot as plt

        plt.close(self.figure)

    def _draw_static(self) -> None:
        from matplotlib.collections import LineCollection, PolyCollection

        view = self.view
        self.collections, self.paths = [], []
        for k, (ax, channel) in enumerate(zip(self.axes, self.boxes.panels)):
            ax.set_facecolor(SCENE_COLOURS["background"][0])
            if view.image_space:
                width, height = _image_size(view, channel)
                ax.set_aspect("equal", adjustable="box")
                ax.add_patch(_rectangle(width, height))
                ax.set_xlim(0, width)
                ax.set_ylim(height, 0)
                ax.set_title(f"channel {channel}", fontsize=9, loc="left")
            else:
                ax.set_aspect("equal", adjustable="datalim")
                _draw_map(ax, view)
                ax.update_datalim(self._extent())
                ax.margins(0)
                ax.autoscale_view()
            collection = PolyCollection([], zorder=3)
            ax.add_collection(collection, autolim=False)
            self.collections.append(collection)
            paths = {name: path for row, name in self.names.items() if len(path := self._path(row, k)) > 1}
            lines = LineCollection(
                list(paths.values()),
                colors=[self.colours[name] for name in paths],
                linestyles="dashed",
                linewidths=1.5,
                alpha=0.7,
                zorder=2,
            )
            ax.add_collection(lines, autolim=False)
            self.paths.append(lines)
        self.texts: list = []
        self.label = self.axes[0].text(0.01, 0.01, "", transform=self.axes[0].transAxes, fontsize=10, zorder=5)
        self._draw_timeline()
        title = view.trace.name if self.match is None else _match_title(view, self.match)
        if view.image_space:
            self.figure.suptitle(title, fontsize=11, x=0.01, ha="left")
        else:
            self.axes[0].set_title(title, fontsize=11, loc="left")

    def _path(self, row: int, panel: int) -> np.ndarray:
        keep = (self.boxes.object == row) & (self.boxes.panel == panel)
        if self.match is not None:
            keep &= (self.boxes.frame >= self.match.first) & (self.boxes.frame <= self.match.last)
        return self.boxes.centre[keep]

    def _extent(self) -> np.ndarray:
        """Two corners of the area to show: the corresponded objects' (all objects' without a match)
        positions with 15 m around them."""
        rows = np.isin(self.boxes.object, list(self.names)) if self.names else np.ones(len(self.boxes.frame), bool)
        points = self.boxes.centre[rows]
        points = points[np.isfinite(points).all(axis=1)]
        if len(points) == 0:
            return np.array([[0.0, 0.0], [100.0, 100.0]])
        return np.array([points.min(axis=0) - 15, points.max(axis=0) + 15])

    def _draw_timeline(self) -> None:
        ax, view = self.timeline, self.view
        n = view.trace.n_frames
        ax.set_xlim(0, n)
        ax.set_facecolor(SCENE_COLOURS["timeline"][0])
        ax.set_yticks([])
        ax.set_xlabel("frame position")
        if self.names and view.trace.behaviours is not None and not view.image_space:
            _label_rows(ax, view, self.names)
        else:
            counts = np.diff(self.offsets)
            marked = np.bincount(self.boxes.frame[self.boxes.marked], minlength=n)
            ax.bar(np.arange(n), counts, width=1.0, align="edge", color=SCENE_COLOURS["count"][0], label="objects")
            if marked.any():
                ax.bar(np.arange(n), marked, width=1.0, align="edge", color=MARKED_COLOUR, label="query's classes")
            ax.legend(loc="upper right", fontsize=7)
        if self.match is not None:
            fill, edge_colour = SCENE_COLOURS["window"]
            ax.axvspan(self.match.first, self.match.last + 1, color=fill, alpha=0.2, zorder=3)
            for edge in (self.match.first, self.match.last + 1):
                ax.axvline(edge, color=edge_colour, linewidth=2, zorder=3)
        self.cursor = ax.axvline(0, color="#111", linewidth=1.5)

    def show_frame(self, frame: int) -> None:
        """Draw the boxes of frame position ``frame``, each in its panel."""
        in_window = self.match is not None and self.match.first <= frame <= self.match.last
        for text in self.texts:
            text.remove()
        self.texts = []
        frame_rows = np.arange(self.offsets[frame], self.offsets[frame + 1])
        for k, (ax, collection) in enumerate(zip(self.axes, self.collections)):
            rows = frame_rows[self.boxes.panel[frame_rows] == k]
            faces, edges, widths = [], [], []
            for row, obj in zip(rows.tolist(), self.boxes.object[rows].tolist()):
                name = self.names.get(obj)
                kind = self.boxes.colour[row]
                marked = in_window and bool(self.boxes.marked[row])
                fill = self.colours[name] if name is not None else kind
                faces.append("none" if self.view.image_space and name is None else fill)
                edges.append("#111" if name is not None else MARKED_COLOUR if marked else kind)
                widths.append(2.0 if name is not None or marked else 0.8)
            collection.set_verts(self.boxes.corners[rows])
            collection.set_facecolors(faces)
            collection.set_edgecolors(edges)
            collection.set_linewidths(widths)
            named = [
                (row, obj) for row, obj in zip(rows.tolist(), self.boxes.object[rows].tolist()) if obj in self.names
            ]
            self.texts += [
                ax.annotate(
                    self.names[obj],
                    self.boxes.centre[row],
                    xytext=(8, 8 + 13 * j),
                    textcoords="offset points",
                    fontsize=9,
                    fontweight="bold",
                    zorder=4,
                    arrowprops={"arrowstyle": "-", "color": "#555", "linewidth": 0.6},
                    animated=collection.get_animated(),
                )
                for j, (row, obj) in enumerate(named)
            ]
        self.cursor.set_xdata([frame + 0.5, frame + 0.5])
        time = self.view.trace.frame_time[frame] - self.view.trace.frame_time[0]
        self.label.set_text(f"frame {int(self.view.trace.frame_index[frame])}" + _seconds(f" · {time:.2f} s", time))

    def gif(self, frames: np.ndarray) -> bytes:
        """The frames as an animated GIF at the recording's speed (at most 20 frames/s), 72 dpi.
        The map and the time line are drawn once; each frame redraws only what moves (blitting)."""
        from PIL import Image

        moving = (*self.collections, self.label, self.cursor)
        for artist in moving:
            artist.set_animated(True)
        self.figure.set_dpi(72)
        canvas = self.figure.canvas
        canvas.draw()
        background = canvas.copy_from_bbox(self.figure.bbox)
        images = []
        for frame in frames.tolist():
            self.show_frame(frame)
            canvas.restore_region(background)
            for artist in (*moving, *self.texts):
                artist.axes.draw_artist(artist)
            rgb = np.asarray(canvas.buffer_rgba())[:, :, :3]
            images.append(Image.fromarray(rgb).quantize(colors=96, method=Image.Quantize.FASTOCTREE))
        period = _period(self.view) * (frames[1] - frames[0] if len(frames) > 1 else 1)
        buffer = io.BytesIO()
        duration = max(int(round(1000 * period)), 50)
        images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], duration=duration, loop=0)
        return buffer.getvalue()


def _names(view: TraceView, match: MatchView | None) -> dict[int, str]:
    """Object row -> program name of the match."""
    if match is None:
        return {}
    rows = view.trace.objects.row_of()
    return {rows[object_id]: name for name, object_id in match.correspondence.items()}


def _kind_colours(view: TraceView) -> list[str]:
    colours = class_colours()
    return [colours[kind] for kind in view.trace.objects.kinds()]


def _match_title(view: TraceView, match: MatchView) -> str:
    index, time = view.trace.frame_index, view.trace.frame_time - view.trace.frame_time[0]
    seconds = _seconds(f" ({time[match.first]:.1f}-{time[match.last]:.1f} s)", time[match.first])
    return f"{view.trace.name}: match {match.number}, frames {index[match.first]}-{index[match.last]}{seconds}"


def _seconds(text: str, value: float) -> str:
    """``text`` when the trace has timestamps (``value`` is finite), else ''."""
    return text if np.isfinite(value) else ""


def _period(view: TraceView) -> float:
    """The frame period in seconds (0.1 for a stream without timestamps)."""
    period = view.trace.frame_period
    return period if np.isfinite(period) and period > 0 else 0.1


def _image_size(view: TraceView, channel: str) -> tuple[float, float]:
    """The largest image width and height (pixels) of a channel (1600 x 900 where unknown)."""
    assert view.trace.images is not None
    samples = view.trace.images.samples
    sizes = samples.take(samples.channel == samples.channels.index(channel))
    return float(sizes.image_width.max(initial=0) or 1600), float(sizes.image_height.max(initial=0) or 900)


def _rectangle(width: float, height: float):
    from matplotlib.patches import Rectangle

    face, edge = SCENE_COLOURS["image"]
    return Rectangle((0, 0), width, height, facecolor=face, edgecolor=edge, zorder=0)


def _draw_map(ax, view: TraceView) -> None:
    from matplotlib.collections import PolyCollection

    from .payload import rings

    road_map = view.road_map
    if road_map is None:
        return
    layers = (
        ([lane.polygon for lane in road_map.lanes], *SCENE_COLOURS["lane"]),
        ([area.polygon for area in road_map.intersections], *SCENE_COLOURS["intersection"]),
        ([area.polygon for area in road_map.crosswalks], *SCENE_COLOURS["crosswalk"]),
    )
    for polygons, face, edge in layers:
        found = rings(polygons)
        if found:
            ax.add_collection(
                PolyCollection(found, facecolors=face, edgecolors=edge, linewidths=0.6, alpha=0.9, zorder=1),
                autolim=False,
            )


def _label_rows(ax, view: TraceView, names: dict[int, str]) -> None:
    """One row per corresponded object: its behaviour label set per frame, a colour per set
    (:func:`.style.behaviour_colours`, as the HTML page)."""
    import matplotlib.pyplot as plt

    trace = view.trace
    assert trace.behaviours is not None
    sets, codes = trace.behaviours.distinct_sets()
    colours = behaviour_colours(sets)
    used: dict[int, str] = {}
    for k, (row, name) in enumerate(names.items()):
        mine = trace.states.object == row
        for code in np.unique(codes[mine]).tolist():
            frames = trace.states.frame[mine & (codes == code)]
            ax.broken_barh([(f, 1) for f in frames.tolist()], (k + 0.1, 0.8), color=colours[code])
            used[code] = sets[code] or "(none)"
        ax.text(1, k + 0.5, name, va="center", fontsize=8, fontweight="bold")
    ax.set_ylim(0, len(names))
    handles = [plt.Rectangle((0, 0), 1, 1, color=colours[code]) for code in used]
    ax.legend(handles, list(used.values()), loc="upper right", fontsize=7, ncols=min(len(used), 4))
