"""Writing a clip's frames fast: each frame drawn over a saved background, the pixels encoded by Pillow (GIF)
or piped to ffmpeg (MP4).

A clip's frames share almost everything: walls, axes, title, legend, colour bar. Redrawing the whole figure
for every frame (what matplotlib's animation writers do: each frame is a ``savefig``) spent about 0.3 s a frame
on text layout and tick labels that never change. :class:`BlitFrames` draws the figure once without the
artists that change or that must cover them, keeps those pixels, and per frame restores them and draws only
the frame's own artists, in the order (z-order, then insertion) a full draw would use, so a frame's pixels are
a full draw's. Then the frame's RGBA buffer goes to a :class:`GifFile` or :class:`Mp4File`.
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterable
from pathlib import Path

import numpy as np

#: The encoder of each clip suffix.
ENCODERS = {".gif": "pillow", ".mp4": "ffmpeg"}


def clip_encoder(out: Path) -> str:
    """The encoder for a clip file (Pillow for .gif, ffmpeg for .mp4); a clear error for another suffix, or
    for .mp4 without ffmpeg on PATH. Cheap: callers check before loading any table."""
    suffix = Path(out).suffix.lower()
    if suffix not in ENCODERS:
        raise ValueError(f"cannot write a clip to {out}: the file must end in {' or '.join(ENCODERS)}")
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise ValueError("writing .mp4 needs ffmpeg on PATH, which is not there: write a .gif instead")
    return ENCODERS[suffix]


class BlitFrames:
    """Frames of one figure whose ``ax`` gains and loses artists from frame to frame.

    ``moving`` are artists that stay on the axes but change every frame (a clock's text). The background holds
    everything else except the axes' own artists above z-order 0 (the walls), which are drawn again with each
    frame's artists so that they cover what a full draw has them cover. Call after the layout is fixed.
    """

    def __init__(self, fig, ax, moving: Iterable = ()):
        self.fig, self.ax = fig, ax
        self.moving = list(moving)
        content = [*ax.images, *ax.collections, *ax.patches, *ax.lines, *ax.texts]
        self.covers = [a for a in content if a.get_zorder() > 0 and not any(a is m for m in self.moving)]
        hidden = [a for a in (*self.covers, *self.moving) if a.get_visible()]
        for artist in hidden:
            artist.set_visible(False)
        fig.canvas.draw()
        self.background = fig.canvas.copy_from_bbox(fig.bbox)
        for artist in hidden:
            artist.set_visible(True)

    def grab(self, artists: Iterable) -> np.ndarray:
        """The frame with ``artists`` (this frame's own, already on the axes) as an RGBA array [H, W, 4]."""
        canvas = self.fig.canvas
        canvas.restore_region(self.background)
        # a stable sort keeps the insertion order among equal z-orders: the covers were added first
        for artist in sorted([*self.covers, *self.moving, *artists], key=lambda a: a.get_zorder()):
            if artist.get_visible():
                self.ax.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba()).copy()


class GifFile:
    """An animated GIF written by Pillow when closed: the frames (RGBA, alpha dropped), each shown 1/fps s,
    looping."""

    def __init__(self, path: Path, fps: float):
        self.path, self.fps, self.frames = Path(path), fps, []

    def write(self, rgba: np.ndarray) -> None:
        from PIL import Image

        self.frames.append(Image.fromarray(np.ascontiguousarray(rgba[..., :3]), "RGB"))  # a figure is opaque

    def close(self) -> None:
        first, *rest = self.frames
        first.save(self.path, format="GIF", save_all=True, append_images=rest, duration=round(1000 / self.fps),
                   loop=0)


class Mp4File:
    """An H.264 MP4 written by ffmpeg from raw RGBA frames on its standard input; odd sizes are padded to even
    ones (yuv420p needs them)."""

    def __init__(self, path: Path, fps: float):
        self.path, self.fps, self.process = Path(path), fps, None

    def write(self, rgba: np.ndarray) -> None:
        if self.process is None:
            height, width = rgba.shape[:2]
            self.process = subprocess.Popen(
                ["ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgba", "-s", f"{width}x{height}",
                 "-framerate", f"{self.fps:.6g}", "-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                 "-vcodec", "libx264", "-pix_fmt", "yuv420p", "-f", "mp4", str(self.path)],
                stdin=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            self.process.stdin.write(np.ascontiguousarray(rgba).tobytes())
        except BrokenPipeError:  # ffmpeg stopped: its own message says why
            self.close()
            raise

    def close(self) -> None:
        if self.process is None:
            raise ValueError(f"no frames to write to {self.path}")
        _, err = self.process.communicate()
        if self.process.returncode:
            raise RuntimeError(f"ffmpeg failed writing {self.path}: {err.decode(errors='replace').strip()}")


def clip_file(path: Path, fps: float) -> GifFile | Mp4File:
    """The writer of a clip at ``path`` by its suffix."""
    return GifFile(path, fps) if Path(path).suffix.lower() == ".gif" else Mp4File(path, fps)
