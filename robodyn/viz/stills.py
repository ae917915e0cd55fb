"""Stills, filmstrips and videos of recordings, rendered by headless Chromium.

One Chromium run renders many frames: the recording page answers ``#capture=T1,T2,...``
(see :mod:`robodyn.viz.recording`) by seeking each time and writing the frames as PNG data
URLs into its DOM, which ``--dump-dom`` prints. Frames are exact (no timing guesswork)
and a 90-frame video needs three browser runs, not ninety.

The Chromium flags are :data:`CHROMIUM_FLAGS`, the one list every robodyn capture uses.
WebGL in a headless browser without a GPU needs SwiftShader through ANGLE
(``--use-angle=swiftshader --enable-unsafe-swiftshader``); the older
``--use-gl=swiftshader`` gives a blank page on current Chromium. Set ``ROBODYN_CHROMIUM``
to the browser to use; otherwise ``chromium``, ``chromium-browser``, ``google-chrome`` are
looked up on ``PATH``. Videos need the ``viewer`` extra (imageio, imageio-ffmpeg).
"""

from __future__ import annotations

import base64
import io
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import cast

import numpy as np

from robodyn.common.files import atomic_write_bytes
from robodyn.exceptions import ViewerError

#: Headless Chromium flags for rendering recordings (WebGL on the CPU, nothing networked).
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",  # robodyn may run as root (containers, CI)
    "--disable-gpu",
    "--use-angle=swiftshader",  # WebGL on the CPU: the combination that renders
    "--enable-unsafe-swiftshader",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--mute-audio",
]
#: Frames rendered by one browser run.
BATCH = 30
Progress = Callable[[int, int], None]


def chromium() -> str | None:
    """Path of a Chromium executable (``ROBODYN_CHROMIUM`` first), or ``None``."""
    chosen = os.environ.get("ROBODYN_CHROMIUM")
    if chosen:
        return shutil.which(chosen) or (chosen if os.access(chosen, os.X_OK) else None)
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def _browser() -> str:
    browser = chromium()
    if browser is None:
        raise ViewerError(
            "no Chromium found for stills and videos: install Debian's 'chromium' package (make chromium) or set ROBODYN_CHROMIUM."
        )
    return browser


def _decode(url: str, mode: str = "RGB") -> np.ndarray:
    from PIL import Image

    prefix = "data:image/png;base64,"
    if not url.startswith(prefix):
        raise ViewerError("Chromium returned no image: the page could not render (no WebGL?).")
    with Image.open(io.BytesIO(base64.b64decode(url[len(prefix) :]))) as image:
        return np.asarray(image.convert(mode))


def capture(
    page: str | os.PathLike,
    times: list[float],
    *,
    size: tuple[int, int] = (800, 600),
    hide: tuple[str, ...] = (),
    progress: Progress | None = None,
) -> list[np.ndarray]:
    """Frames of a recording at the given times, as RGB arrays of shape (height, width, 3).

    With ``"Background"`` in ``hide`` the frames are RGBA, shape (height, width, 4), and
    transparent where nothing is drawn (a mask of the robot, measured not assumed).

    Args:
        page: The recording's HTML file (a path) or its text (a ``str`` holding ``<html``).
        times: Times in [s] from the motion's start.
        size: Width and height in [pixel].
        hide: Top-level scene nodes not drawn: ``"task"``, ``"Axes"``, ``"Grid"``, ``"Background"``.
        progress: Called with (frames done, frames in all) after each browser run.

    Raises:
        RobodynError: If no browser is found or it cannot render the page.
    """
    browser = _browser()
    with tempfile.TemporaryDirectory(prefix="robodyn-chromium-") as folder:
        if isinstance(page, str) and "<html" in page[:200]:
            html = Path(folder) / "recording.html"
            html.write_text(page, encoding="utf-8")
        else:
            html = Path(page).resolve()
        frames: list[np.ndarray] = []
        for start in range(0, len(times), BATCH):
            batch = times[start : start + BATCH]
            hidden = f"&hide={','.join(hide)}" if hide else ""
            url = f"{html.as_uri()}#size={size[0]}x{size[1]}{hidden}&capture={','.join(f'{t:.6f}' for t in batch)}"
            command = [
                browser, *CHROMIUM_FLAGS, f"--user-data-dir={Path(folder) / 'profile'}",
                f"--window-size={size[0]},{size[1]}", "--virtual-time-budget=2000", "--dump-dom", url,
            ]  # fmt: skip
            try:
                result = subprocess.run(command, capture_output=True, timeout=300, check=False)
            except (OSError, subprocess.TimeoutExpired) as error:
                raise ViewerError(f"Chromium ({browser}) could not run: {error}.") from None
            dom = result.stdout.decode("utf-8", "replace")
            begin, end = dom.find('<pre id="frames">'), dom.find("</pre>")
            urls = dom[begin + len('<pre id="frames">') : end].split() if begin >= 0 and end > begin else []
            if result.returncode != 0 or len(urls) != len(batch):
                detail = result.stderr.decode("utf-8", "replace").strip().splitlines()
                reason = detail[-1][:160] if detail else f"exit {result.returncode}"
                raise ViewerError(
                    f"Chromium ({browser}) did not render the recording ({reason}); see CHROMIUM_FLAGS in robodyn.viz.stills."
                )
            decoded = [_decode(u, "RGBA" if "Background" in hide else "RGB") for u in urls]
            if any(frame.shape[:2] != (size[1], size[0]) for frame in decoded):
                raise ViewerError(
                    f"Chromium rendered {decoded[0].shape[1]}x{decoded[0].shape[0]} frames, not {size[0]}x{size[1]}."
                )
            frames += decoded
            if progress is not None:
                progress(len(frames), len(times))
    return frames


def _png(image: np.ndarray) -> bytes:
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG")
    return buffer.getvalue()


def still_of_page(page: str | os.PathLike, png: str | os.PathLike, *, at: float = 0.0, size=(800, 600)) -> Path | None:
    """A PNG of the recording's frame at ``at`` seconds (written atomically; ``None`` for ``-``).

    Args:
        page: The recording's HTML file (a path) or its text (a ``str`` holding ``<html``).
        png: The PNG file to write, or ``"-"`` for standard output.
        at: Time into the animation in [s].
        size: Width and height in pixels.
    """
    return atomic_write_bytes(png, _png(capture(page, [at], size=size)[0]))


def screenshot(
    html: str | os.PathLike, png: str | os.PathLike, *, at_seconds: float = 0.0, size: tuple[int, int] = (800, 600)
) -> Path | None:
    """A PNG of an HTML recording ``at_seconds`` into its animation (headless Chromium);
    the file written, ``None`` for standard output (``-``).

    Args:
        html: The recording's HTML file.
        png: The PNG file to write, or ``"-"`` for standard output.
        at_seconds: Time into the animation in [s].
        size: Width and height in pixels.
    """
    return still_of_page(Path(html), png, at=at_seconds, size=size)


def evenly(duration: float, count: int) -> list[float]:
    """``count`` times from the start to the end of a motion, in [s].

    Args:
        duration: Duration of the motion in [s].
        count: Number of times, 1 to 60.
    """
    if not (isinstance(count, int) and 1 <= count <= 60):
        raise ViewerError(f"a filmstrip has 1 to 60 frames, got {count}.")
    return [float(t) for t in np.linspace(0.0, duration, count)] if count > 1 else [0.0]


def filmstrip_of_page(
    page: str | os.PathLike, png: str | os.PathLike, duration: float, count: int, *, size=(480, 360), columns: int = 6
) -> Path | None:
    """``count`` frames evenly over the motion, side by side (rows of ``columns``), each
    labelled with its time; the file written, ``None`` for standard output (``-``).

    Args:
        page: The recording's HTML file (a path) or its text (a ``str`` holding ``<html``).
        png: The PNG file to write, or ``"-"`` for standard output.
        duration: Duration of the motion in [s].
        count: Number of frames, 1 to 60.
        size: Width and height of each frame in pixels.
        columns: Most frames a row.
    """
    from PIL import Image, ImageDraw

    times = evenly(duration, count)
    frames = capture(page, times, size=size)
    columns = min(columns, count)
    rows = -(-count // columns)
    sheet = Image.new("RGB", (columns * size[0], rows * size[1]), "white")
    draw = ImageDraw.Draw(sheet)
    for index, (time, frame) in enumerate(zip(times, frames, strict=True)):
        x, y = (index % columns) * size[0], (index // columns) * size[1]
        sheet.paste(Image.fromarray(frame), (x, y))
        draw.rectangle((x, y, x + 84, y + 18), fill="white")
        draw.text((x + 4, y + 3), f"t = {time:.2f} s", fill="black")
    buffer = io.BytesIO()
    sheet.save(buffer, format="PNG")
    return atomic_write_bytes(png, buffer.getvalue())


def _stderr_progress(done: int, total: int) -> None:
    print(f"\rrobodyn: rendered {done}/{total} frames", end="\n" if done == total else "", file=sys.stderr, flush=True)


def video_of_page(
    page: str | os.PathLike,
    path: str | os.PathLike,
    duration: float,
    *,
    fps: float = 15.0,
    size: tuple[int, int] = (640, 480),
    progress: Progress | None = _stderr_progress,
) -> Path:
    """An MP4 (H.264) or GIF of the motion, by the file's extension, written atomically.

    Args:
        page: The recording's HTML file (a path) or its text (a ``str`` holding ``<html``).
        path: The ``.mp4`` or ``.gif`` file to write.
        duration: Duration of the motion in [s].
        fps: Frames per second of the video.
        size: Width and height in pixels.
        progress: Called with ``(frames done, frames in all)`` after each browser run (``None``: silent; default: a counter on
            stderr).

    Raises:
        RobodynError: For another extension, a bad ``fps``, or without the ``viewer`` extra.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in (".mp4", ".gif"):
        raise ViewerError(f"a video is .mp4 or .gif, got {str(path)!r}.")
    if not (np.isfinite(fps) and 1 <= fps <= 60):
        raise ViewerError(f"video fps must lie in [1, 60], got {fps:g}.")
    if size[0] % 16 or size[1] % 16:
        raise ViewerError(f"video sizes are multiples of 16 pixels (H.264), got {size[0]}x{size[1]}.")
    try:
        import imageio.v2 as imageio
    except ImportError:
        raise ViewerError(
            "videos need imageio: pip install imageio imageio-ffmpeg (or '.[viewer]' in robodyn's clone)."
        ) from None
    count = int(np.floor(duration * fps + 1e-9)) + 1
    if count > 3600:
        raise ViewerError(f"the video would have {count} frames (over 3600): lower the frame rate (fps=) or shorten the motion.")
    frames = capture(page, [k / fps for k in range(count)], size=size, progress=progress)
    with tempfile.TemporaryDirectory(prefix="robodyn-video-") as folder:
        scratch = Path(folder) / f"video{suffix}"
        if suffix == ".mp4":
            try:
                writer = imageio.get_writer(
                    scratch, fps=fps, codec="libx264", quality=8, pixelformat="yuv420p", macro_block_size=16
                )
            except (ImportError, ValueError, RuntimeError) as error:
                raise ViewerError(
                    f"no MP4 writer ({error}): pip install imageio-ffmpeg (or '.[viewer]' in robodyn's clone)."
                ) from None
            with writer:
                for frame in frames:
                    writer.append_data(frame)
        else:
            # the stub asks for an (invariant) list of ArrayLike; a list of arrays is one
            imageio.mimsave(scratch, frames, duration=1000.0 / fps, loop=0)  # type: ignore[arg-type]
        written = atomic_write_bytes(path, scratch.read_bytes())
    return cast(Path, written)  # never None: the extension check refused "-"
