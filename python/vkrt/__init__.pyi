# Type hints for the vkrt package (python/vkrt/__init__.py; docs/python.md).
from os import PathLike
from typing import Any, Iterator, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike[str]]
_Vec3 = Sequence[float]
_Image = npt.NDArray[np.float32]

AOVS: tuple[str, ...]

class SceneError(ValueError):
    file: str
    line: Optional[int]
    column: Optional[int]
    message: str

class VkrtError(RuntimeError): ...

class Scene:
    @classmethod
    def load(cls, path: _Path) -> Scene: ...
    @classmethod
    def from_toml(cls, text: str, base_dir: _Path = ...) -> Scene: ...
    @property
    def source(self) -> str: ...
    def info(self) -> dict[str, Any]: ...
    @property
    def camera(self) -> dict[str, Any]: ...
    def set_camera(
        self,
        eye: Optional[_Vec3] = ...,
        target: Optional[_Vec3] = ...,
        up: Optional[_Vec3] = ...,
        fov: Optional[float] = ...,
        aperture: Optional[float] = ...,
        focus_distance: Optional[float] = ...,
    ) -> None: ...
    @property
    def materials(self) -> list[str]: ...
    def set_material(self, name: str, **table: Any) -> None: ...
    def copy(self) -> Scene: ...

class Result:
    image: _Image
    variance: Optional[_Image]
    albedo: Optional[_Image]
    normal: Optional[_Image]
    position: Optional[_Image]
    depth: Optional[_Image]
    metadata: dict[str, Union[str, int, float]]
    spp: int
    render_seconds: float
    stopped_by: str
    interrupted: bool
    error_estimate: Optional[dict[str, float]]
    def save(self, path: _Path, exposure: float = ..., filmic: bool = ...) -> None: ...

def render(
    scene: Scene,
    spp: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    seed: int = ...,
    sampler: str = ...,
    integrator: Optional[str] = ...,
    device: str = ...,
    time_budget: Optional[float] = ...,
    target_error: Optional[float] = ...,
    variance: bool = ...,
    aovs: Sequence[str] = ...,
    accel: str = ...,
) -> Result: ...
def progressive(
    scene: Scene,
    batches: int = ...,
    spp_per_batch: int = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    seed: int = ...,
    sampler: str = ...,
    integrator: Optional[str] = ...,
    device: str = ...,
    variance: bool = ...,
    aovs: Sequence[str] = ...,
    accel: str = ...,
) -> Iterator[Result]: ...
def devices() -> list[dict[str, Any]]: ...
def read_exr(path: _Path) -> tuple[dict[str, _Image], dict[str, Union[str, int, float]]]: ...
def measure_error(image: npt.ArrayLike, reference: npt.ArrayLike) -> dict[str, float]: ...
