"""An animation's frames, drawn fast and written as a GIF or an MP4.

A frame is drawn by blitting: the figure once without the artists that change, and on
that background only they (the axes, ticks, labels and colorbar, most of a full
redraw's time, do not change). A GIF keeps one palette for every frame, so that what
does not move stays the same and each frame stores only what changed; an MP4 (H.264)
is written by imageio-ffmpeg's ffmpeg.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.files import atomic_path

#: Pixels per inch of the animation's frames
DPI = 80
#: A GIF's colours: one palette for every frame, so that what does not move stays the
#: same and each frame stores only what changed
GIF_COLOURS = 64


def blit_frames(fig, draw, frames, moving, dpi=None):
    """The frames as RGB arrays: the figure drawn once without the ``moving`` artists,
    and on that background only they, frame by frame (the axes, ticks and labels, most
    of a full redraw's time, do not change)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Text

    draw(frames[0])  # the first frame's time stamp is in the layout
    fig.set_dpi(DPI if dpi is None else dpi)
    canvas = FigureCanvasAgg(fig)
    fig.draw_without_rendering()
    fig.set_layout_engine("none")  # laid out once: the frames must not move the axes
    # the background without them: a text emptied (a hidden title would be placed off
    # the figure), the rest hidden
    texts = {a: a.get_text() for a in moving if isinstance(a, Text)}
    for artist in moving:
        artist.set_text("") if artist in texts else artist.set_visible(False)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    for artist in moving:
        artist.set_text(texts[artist]) if artist in texts else artist.set_visible(True)
    for k in frames:
        draw(k)
        canvas.restore_region(background)
        for artist in moving:
            fig.draw_artist(artist)
        yield np.asarray(canvas.buffer_rgba())[..., :3].copy()


def write_gif(path, frames_rgb, fps):
    """Write the RGB frames (arrays) to a GIF at ``fps`` frames a second."""
    from PIL import Image

    first, *rest = (Image.fromarray(rgb) for rgb in frames_rgb)
    palette = first.quantize(colors=GIF_COLOURS, method=Image.Quantize.MEDIANCUT)
    rest = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in rest]
    palette.save(path, format="GIF", save_all=True, append_images=rest, loop=0,
                 duration=round(1000 / fps))


def write_mp4(path, frames_rgb, fps):
    """Write the RGB frames (an iterator of arrays) to an MP4 (ffmpeg, libx264) at ``fps``
    frames a second."""
    import imageio_ffmpeg

    first = next(frames_rgb)
    height, width = first.shape[:2]
    writer = imageio_ffmpeg.write_frames(path, (width, height), fps=fps, codec="libx264",
                                         pix_fmt_out="yuv420p", macro_block_size=2,
                                         output_params=["-f", "mp4"])
    writer.send(None)  # start ffmpeg
    try:
        for rgb in (first, *frames_rgb):
            writer.send(np.ascontiguousarray(rgb))
    finally:
        writer.close()


def ffmpeg_available() -> bool:
    """Whether an ffmpeg binary is at hand (imageio-ffmpeg's, or one it finds)."""
    try:
        import imageio_ffmpeg

        imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        return False
    return True


def write_frames(path, frames_rgb, fps) -> Path:
    """Write the RGB frames to ``path`` (atomically), a GIF or an MP4 by its suffix."""
    path = Path(path)
    fmt = path.suffix.lower()
    if fmt not in (".gif", ".mp4"):
        raise ValueError(f"path: must end in .gif or .mp4, got {path.name!r}")
    with atomic_path(path, suffix=fmt) as tmp:
        (write_gif if fmt == ".gif" else write_mp4)(tmp, frames_rgb, fps)
    return path


def default_format() -> tuple[str, str | None]:
    """The animation's format when none is asked for: ``"mp4"`` where ffmpeg is at hand
    (smaller and faster to write), else ``"gif"`` with a line saying why."""
    if ffmpeg_available():
        return "mp4", None
    return "gif", "no ffmpeg found (pip install imageio-ffmpeg for MP4): writing a GIF"


__all__ = ["DPI", "GIF_COLOURS", "blit_frames", "default_format", "ffmpeg_available",
           "write_frames", "write_gif", "write_mp4"]
