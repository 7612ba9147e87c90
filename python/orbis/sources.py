"""orbis.sources: videos, image folders and live cameras as iterators of frames.

Contract: each function opens its input at once (a missing file, folder or camera raises
orbis.Error naming it) and returns a Source, an iterator of SourceFrame (``index``,
``timestamp`` in seconds, ``image`` as a NumPy array, ``right``/``depth`` or None). A camera,
a stream, or any source opened with ``realtime=True`` is live: a loop slower than the camera
gets the newest frame and ``source.dropped`` counts the rest.

Example (a webcam)::

    import orbis
    slam = orbis.MonocularSlam(orbis.Settings.load("my_camera.yaml", sensor="mono"))
    with orbis.sources.camera(0) as frames:
        for frame in frames:
            state, pose = slam.track(frame.image, frame.timestamp)
"""

from __future__ import annotations

from ._orbis import sources as _sources

Source = _sources.Source
SourceFrame = _sources.SourceFrame
video = _sources.video
images = _sources.images
camera = _sources.camera

__all__ = ["Source", "SourceFrame", "camera", "images", "video"]
