"""The exceptions volpt raises. Every one carries the Rust library's message: the file and line,
the field or option, what was expected and what was found.

    VolptError
    ├── SceneError           a scene file that cannot be read or rendered
    │   └── SceneNotFoundError   (also a FileNotFoundError)
    ├── SettingsError        a bad keyword argument or load setting (also a ValueError)
    ├── ParamError           a scene parameter's bad value (also a ValueError)
    │   └── UnknownParamError    a key that is no parameter (also a KeyError)
    ├── GridError            grid values of the wrong shape or range, or for no grid (also a ValueError)
    ├── RenderError          the CPU or GPU backend failed (no GPU, no kernels in this build)
    ├── CheckpointError      a film file that cannot be read or written, or of another render
    ├── MergeError           films that do not add up to one render (also a ValueError)
    └── ImageError           an image that cannot be written or read
"""


class VolptError(Exception):
    """Base class of every error volpt raises."""


class SceneError(VolptError):
    """A scene file that cannot be read or describes something volpt cannot render."""


class SceneNotFoundError(SceneError, FileNotFoundError):
    """A scene file, or a file it names, that does not exist."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class SettingsError(VolptError, ValueError):
    """A setting or keyword argument that is out of range or contradicts another."""


class ParamError(VolptError, ValueError):
    """A scene parameter (``scene.params[key] = value``) with a value of the wrong type or range.
    The scene is left as it was."""


class UnknownParamError(ParamError, KeyError):
    """A key of ``scene.params`` that is no parameter."""

    def __str__(self) -> str:  # KeyError quotes its message; this one is a sentence.
        return str(self.args[0]) if self.args else ""


class GridError(VolptError, ValueError):
    """Grid values (``scene.set_grid``) for a grid the scene lacks, of the wrong shape, or out of
    range. The scene is left as it was."""


class RenderError(VolptError):
    """The CPU or GPU backend failed (including: no GPU, no kernels in this build)."""


class CheckpointError(VolptError):
    """A film file that cannot be read or written, or is of another render."""


class MergeError(VolptError, ValueError):
    """Films that do not add up to one render: of another scene, seed or size, or of
    overlapping sample ranges or ranges with a gap between them."""


class ImageError(VolptError):
    """An image that cannot be written or read."""


class PrintError(VolptError, ValueError):
    """A colour 3D print's compensation that cannot run: a target or material table volpt cannot
    read (the file, field, expected and found values), an output folder already holding a
    record's slices, or arguments out of range."""


__all__ = [
    "VolptError",
    "SceneError",
    "SceneNotFoundError",
    "SettingsError",
    "ParamError",
    "UnknownParamError",
    "GridError",
    "RenderError",
    "CheckpointError",
    "MergeError",
    "ImageError",
    "PrintError",
]
