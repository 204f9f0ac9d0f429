"""Input and output: atomic writes, video, motion files (BVH, Kinect CSV, truth sidecars)."""

from .atomic import atomic_path, write_bytes, write_text

__all__ = ["atomic_path", "write_bytes", "write_text"]
