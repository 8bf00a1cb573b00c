"""Offscreen frames of the gripper cell, only when asked (`viscoadh gripper --frames DIR`).

MuJoCo renders offscreen through the backend named by ``MUJOCO_GL``, read when ``mujoco`` is
first imported: ``egl`` (GPU or Mesa's EGL, package libegl1) or ``osmesa`` (software, package
libosmesa6), which `viscoadh gripper --frames` sets to ``egl`` when unset and checks before
the first ``import mujoco`` of the process; `FrameRecorder` then writes PNGs
(``frame_00000.png`` ..) at ``fps`` frames per simulated second. Figures never need any of
this (matplotlib Agg).
"""

from __future__ import annotations

import os
from pathlib import Path

from viscoadh_ros.core.errors import InputError

BACKENDS = ("egl", "osmesa")
#: What each backend needs on a Debian/Ubuntu machine.
PACKAGES = {"egl": "libegl1 (and a GPU driver or Mesa)", "osmesa": "libosmesa6"}


class FrameRecorder:
    """Renders the cell every 1/fps simulated seconds into ``folder`` (created)."""

    def __init__(self, folder: Path, *, fps: float = 30.0, width: int = 480, height: int = 360) -> None:
        self.folder = folder
        self.period = 1.0 / fps
        self.width, self.height = width, height
        self._renderer = None
        self._camera = None
        self._next = 0.0
        self.count = 0

    def start(self, model) -> None:
        """Open the offscreen context for ``model``; InputError naming the missing backend."""
        import mujoco

        backend = os.environ.get("MUJOCO_GL", "egl").lower()
        try:
            self._renderer = mujoco.Renderer(model, self.height, self.width)
        except Exception as error:  # the backends fail with many exception types
            raise InputError(
                f"--frames: MuJoCo's {backend} backend did not start ({type(error).__name__}: "
                f"{str(error).strip() or 'no detail'}); install {PACKAGES[backend]} or set "
                f"MUJOCO_GL to the other of {' / '.join(BACKENDS)}"
            ) from None
        camera = mujoco.MjvCamera()
        camera.lookat[:] = (0.0, 0.0, 0.01)
        camera.distance, camera.azimuth, camera.elevation = 0.12, 90.0, -15.0
        self._camera = camera
        self.folder.mkdir(parents=True, exist_ok=True)

    def __call__(self, model, data, time: float) -> None:
        """Write a frame if one is due at ``time`` (s)."""
        if time + 1e-12 < self._next:
            return
        if self._renderer is None:
            self.start(model)
        import matplotlib.image

        self._renderer.update_scene(data, camera=self._camera)
        matplotlib.image.imsave(self.folder / f"frame_{self.count:05d}.png", self._renderer.render())
        self.count += 1
        self._next += self.period

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
