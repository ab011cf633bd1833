"""Rendering: the scene's lights and offscreen buffer (`set_visual_options`), the camera check
(`check_camera`) and the Gymnasium MuJoCo renderer (`make_renderer`, `DEFAULT_CAMERA`)."""

from __future__ import annotations

from typing import Any

import mujoco

__all__ = [
    "DEFAULT_CAMERA",
    "check_camera",
    "close_renderer",
    "make_renderer",
    "render_frame",
    "set_visual_options",
]

DEFAULT_CAMERA = {"distance": 14.0, "elevation": -20.0, "azimuth": 135.0, "trackbodyid": 1}
"""The free camera of an env rendered without a `camera_name`."""


def set_visual_options(spec: mujoco.MjSpec, size: tuple[int, int]) -> None:
    """The head light, a sun, and an offscreen buffer of at least `size` (width, height)."""
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.65, 0.65, 0.65]
    spec.worldbody.add_light(
        name="sun", pos=[0, 0, 30], dir=[0.3, 0.2, -1.0], diffuse=[0.5, 0.5, 0.5]
    )
    spec.visual.global_.offwidth = max(size[0], 640)
    spec.visual.global_.offheight = max(size[1], 480)


def check_camera(model: mujoco.MjModel, camera_name: str | None) -> None:
    """Refuse a `camera_name` that is not a camera of `model` (None: the free camera)."""
    cameras = [model.camera(i).name for i in range(model.ncam)]
    if camera_name is not None and camera_name not in cameras:
        raise ValueError(
            f"camera_name {camera_name!r} is not a camera of the model; valid: "
            f"{cameras}, or None (the free camera)"
        )


def make_renderer(
    model: mujoco.MjModel, data: mujoco.MjData, camera_name: str | None, size: tuple[int, int]
) -> Any:
    """A Gymnasium `MujocoRenderer` of `model` from the named camera, or from the free camera
    at `DEFAULT_CAMERA`."""
    from gymnasium.envs.mujoco.mujoco_rendering import MujocoRenderer

    cam_id = None
    if camera_name is not None:
        cam_id = model.camera(camera_name).id
    return MujocoRenderer(
        model,
        data,
        default_cam_config=None if cam_id is not None else DEFAULT_CAMERA,
        width=size[0],
        height=size[1],
        camera_id=cam_id,
    )


def render_frame(renderer: Any, render_mode: str) -> Any:
    """`renderer.render(render_mode)` with its viewer's OpenGL context made current first.

    Gymnasium's `MujocoRenderer` makes a context current only when one renderer holds two
    viewers. With two envs rendering in one process, a frame would then be drawn in the context
    made last, with the other env's meshes and textures: a wrong picture, or a black one once
    the other env is closed."""
    renderer._get_viewer(render_mode).make_context_current()
    return renderer.render(render_mode)


def close_renderer(renderer: Any) -> None:
    """Close `renderer`'s viewers, each freeing its MuJoCo render context (`MjrContext`: the
    framebuffers, textures and meshes on the GPU) with its own OpenGL context current.

    Freed later, by garbage collection, the context's objects would be deleted by number in
    whichever OpenGL context is current then: another env's, whose frames turn black.
    Gymnasium's `close()` of an offscreen viewer also terminates GLFW, which with
    ``MUJOCO_GL=glfw`` would destroy every other env's context: an offscreen viewer frees its
    own context only; a window ("human") is closed as Gymnasium closes it."""
    from gymnasium.envs.mujoco.mujoco_rendering import OffScreenViewer

    for viewer in renderer._viewers.values():
        viewer.make_context_current()
        viewer.con.free()
        if isinstance(viewer, OffScreenViewer):
            viewer.free()
        else:
            viewer.close()
    renderer._viewers.clear()
