"""Render a score or a motion to a folder: video, truth sidecar and the score.

``render_score(score, outdir)`` writes ``OUTDIR/video.mp4``,
``OUTDIR/truth.npz`` and ``OUTDIR/score.lab``; each file is written
atomically.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import asdict
from pathlib import Path

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index, rotation_front
from capture2notation.errors import SyntheticError
from capture2notation.io.calibration import Calibration, CameraCalibration, camera_name, write_calibration
from capture2notation.io.truth import write_truth

from .camera import VIEWS, Camera
from .mannequin import Mannequin
from .markers import Markers
from .scene import Pose, landmark_visibility
from .stick import Stick
from .video import open_writer

__all__ = [
    "CAMERA_FILE",
    "STYLES",
    "make_renderer",
    "render_frames",
    "render_motion",
    "render_pose",
    "render_score",
    "truth_fields",
    "write_camera_toml",
]

#: Rendering styles by name.
STYLES = {"mannequin": Mannequin, "stick": Stick, "markers": Markers}


def make_renderer(pose: Pose, camera: Camera, style: str = "mannequin"):
    """The style's renderer: ``len(r)`` frames, ``r.frame(i)`` → (H, W, 3) uint8 BGR."""
    if style not in STYLES:
        raise SyntheticError(f"unknown style {style!r}; expected one of {', '.join(STYLES)}")
    return STYLES[style](pose, camera)


def render_frames(pose: Pose, camera: Camera, style: str = "mannequin") -> Iterator[np.ndarray]:
    """Yield the frames of `pose` seen by `camera`, (H, W, 3) uint8 BGR each."""
    r = make_renderer(pose, camera, style)
    for i in range(len(r)):
        yield r.frame(i)


def truth_fields(
    pose: Pose, camera: Camera, *, score_json: str = "null", effort_json: str = "null", view: str = "", style: str = ""
) -> dict:
    """Every field of the truth sidecar for `pose` seen by `camera`.

    Returns
    -------
    dict
        Keyword arguments for :func:`capture2notation.io.truth.write_truth`.
    """
    return {
        "fps": pose.fps,
        "times": pose.times,
        "joint_names": np.array(JOINTS),
        "joints": pose.joints,
        "angles": pose.angles,
        "root": pose.root,
        "landmarks3d": pose.landmarks,
        "keypoints": camera.project(pose.landmarks),
        "visibility": landmark_visibility(pose, camera),
        "K": camera.K,
        "R": camera.R,
        "t": camera.t,
        "image_size": np.array(camera.size),
        "score": score_json,
        "effort": effort_json,
        "view": view,
        "style": style,
        "body_height": pose.body.height,
        "front": rotation_front(pose.rotations[:, joint_index("pelvis")]),
    }


def render_pose(
    pose: Pose,
    outdir,
    *,
    size=(640, 480),
    view: str = "front",
    style: str = "mannequin",
    video_name: str = "video.mp4",
    score_json: str = "null",
    effort_json: str = "null",
    progress: bool = False,
    camera: Camera | None = None,
) -> Path:
    """Render `pose` into `outdir`: the frames, their ``truth.npz`` and ``camera.toml``.

    Parameters
    ----------
    pose : Pose
    outdir : str or Path
        Created if needed.
    size : (int, int)
        Image (width, height), pixels (ignored when `camera` is given).
    view : {"front", "45", "side"}
        Preset camera (:meth:`Camera.for_view`); recorded in the truth.
    style : {"mannequin", "stick", "markers"}
    video_name : str
        ``*.mp4`` for a video, a name without suffix for a PNG folder.
    score_json, effort_json : str
        JSON text stored in the truth sidecar.
    progress : bool
        Show a progress bar over frames.
    camera : Camera, optional
        Use this camera instead of the `view` preset.

    Returns
    -------
    Path
        The video file (or frame folder).
    """
    outdir = Path(outdir)
    camera = camera if camera is not None else Camera.for_view(view, size, pose.body.height)
    renderer = make_renderer(pose, camera, style)
    fields = truth_fields(pose, camera, score_json=score_json, effort_json=effort_json, view=view, style=style)
    video = outdir / video_name
    frames = range(len(renderer))
    if progress:
        from capture2notation.progress import progress as progress_bar

        frames = progress_bar(frames, desc=f"render {style} {view}", unit="frame", leave=False)
    with open_writer(video, pose.fps, camera.size) as writer:
        for i in frames:
            writer.write(renderer.frame(i))
    write_truth(outdir / "truth.npz", **fields)
    write_camera_toml(camera, outdir / CAMERA_FILE, name=camera_name(outdir.resolve()))
    return video


#: The render's camera as a calibration file, beside its video: an experiment
#: passes it explicitly (``c2n capture VIDEO --calibration OUT/camera.toml``);
#: a capture never reads it on its own (DESIGN.md, "What a capture may know").
CAMERA_FILE = "camera.toml"


def perform_score(score, fps: float, body: Body, style: str, emotion: str | None = None):
    """The score as the dancer performs it: `style` checked, `emotion` applied, the motion interpreted.

    Returns
    -------
    score : Score
        With the emotion's Effort when one is given.
    motion : Motion
    """
    from ..interpret import interpret

    if style not in STYLES:
        raise SyntheticError(f"unknown style {style!r}; expected one of {', '.join(STYLES)}")
    if emotion is not None:
        score = score.with_emotion(emotion)
    return score, interpret(score, fps, body)


def write_camera_toml(camera: Camera, path, name: str) -> Path:
    """Write `camera` as a one-camera calibration file named `name` (no distortion)."""
    cam = CameraCalibration(
        name, tuple(int(v) for v in camera.size), np.asarray(camera.K), np.zeros(5), camera.R, camera.t
    )
    return write_calibration(Calibration.of([cam]), path, comment="the renderer's true camera")


def render_motion(motion, outdir, **kw) -> Path:
    """Render a ``synthetic.motion.Motion`` (anything with fps, angles, root, body); see :func:`render_pose`."""
    return render_pose(Pose.from_motion(motion), outdir, **kw)


def render_score(
    score,
    outdir,
    fps: float = 25.0,
    size=(640, 480),
    view: str = "front",
    style: str = "mannequin",
    emotion: str | None = None,
    progress: bool = True,
    body: Body | None = None,
    video_name: str = "video.mp4",
    audio: str | None = None,
    camera: Camera | None = None,
) -> Path:
    """Perform a score with the virtual dancer and render it.

    Writes ``OUTDIR/video.mp4`` (or `video_name`), ``OUTDIR/truth.npz`` and
    ``OUTDIR/score.lab``.

    Parameters
    ----------
    score : capture2notation.notation.Score
    outdir : str or Path
    fps : float
        Frames per second.
    size : (int, int)
        Image (width, height), pixels.
    view : {"front", "45", "side"}
    style : {"mannequin", "stick", "markers"}
    emotion : str, optional
        Perform with this emotion preset (its Effort and tempo).
    progress : bool
        Show a progress bar over frames.
    body : Body, optional
        Default ``Body()``.
    video_name : str
        ``*.mp4`` for a video, a name without suffix for a folder of PNG frames.
    audio : str, optional
        Sound for the mp4: ``"click"`` (a click track at the score's tempo,
        the first beat of each measure accented) or a music file's path
        (:func:`synthetic.render.sound.add_sound`).
    camera : Camera, optional
        Use this camera (e.g. :meth:`Camera.phone`) instead of the `view` preset.

    Returns
    -------
    Path
        The output folder.
    """
    from capture2notation.notation.formats import dumps, write

    if view not in VIEWS:
        raise SyntheticError(f"unknown view {view!r}; expected one of {', '.join(VIEWS)}")
    score, motion = perform_score(score, fps, body or Body(), style, emotion)
    outdir = Path(outdir)
    render_motion(
        motion,
        outdir,
        size=size,
        view=view,
        style=style,
        score_json=dumps(score, "json"),
        effort_json=json.dumps(asdict(score.resolved_effort())),
        progress=progress,
        video_name=video_name,
        camera=camera,
    )
    if audio is not None:
        from .sound import add_sound

        add_sound(outdir / video_name, audio, score.tempo, score.meter, motion.angles.shape[0] / float(motion.fps))
    write(score, outdir / "score.lab")
    return outdir
