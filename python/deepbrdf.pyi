"""Type stubs of the deepbrdf module (python/src/*.rs; docs/python.md).

Measured BRDFs (MERL `.binary`, RGL `.bsdf`, the bundled materials) and the DeepBRDF
representation (Hu et al. 2020) from numpy. A table is a float32 array of shape
(3, 90, 90, 180) (colour channel, theta_h, theta_d, phi_d) of BRDF values in 1/sr with NaN for
invalid (below-horizon) cells; a latent vector is float32 (k,); an image is float32 (H, W, 3)
linear radiance, or (H, W, 4) with the coverage as fourth channel.
"""

import os
import pathlib
from typing import Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, "os.PathLike[str]"]
Table = npt.NDArray[np.float32]
ArrayLike = npt.ArrayLike

DEFAULT_MODEL_DIR: str
"""The shipped model's directory (`models/default` of the checkout the package was built from)."""

class FileFormatError(OSError):
    """A file that exists but is not what its format requires; the message names it."""

def read_merl(path: PathLike) -> Table:
    """Reads a MERL `.binary` file: (3, 90, 90, 180) float32 in 1/sr, NaN for invalid cells.

    Raises an OSError subclass naming the file (FileNotFoundError, ..., FileFormatError)."""

def write_merl(path: PathLike, table: ArrayLike) -> None:
    """Writes a table as a MERL `.binary` file, atomically, as `experiments` writes it.

    Raises ValueError for a bad array, OSError for the file."""

def read_bsdf(path: PathLike) -> Table:
    """Reads an RGL `.bsdf` measurement tabulated on the MERL grid (`experiments convert`)."""

def write_bsdf(
    path: PathLike,
    table: Table,
    *,
    description: str = "table",
    theta_i: Optional[int] = None,
    ndf: Optional[int] = None,
    vndf: Optional[int] = None,
    rgb: Optional[int] = None,
) -> None:
    """Writes a table as an isotropic RGB RGL `.bsdf` file (Mitsuba 3's and pbrt-v4's
    `measured` materials read it), byte for byte as `experiments export-bsdf` writes it for the
    same description and resolutions (its defaults when None)."""

def bundled(name: str) -> Table:
    """A bundled material by name (`chrome`, `merl/chrome`, `rgl/cardboard_rgb`,
    `rgl-measured/paper_white_rgb`), tabulated on first use and cached. The `merl`,
    `nielsen2015` and `rgl` collections are Neural-BRDF fits, not the measurements."""

def bundled_names(collection: Optional[str] = None) -> list[str]:
    """The bundled materials as `collection/name`: of `merl`, `nielsen2015`, `rgl`,
    `rgl-measured`, or of all four."""

def render(
    table: ArrayLike,
    *,
    shape: Optional[str] = None,
    light: Optional[str] = None,
    view: Optional[Tuple[float, float]] = None,
    fov: Optional[float] = None,
    size: Optional[int] = None,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    sampler: Optional[str] = None,
    alpha: bool = False,
) -> npt.NDArray[np.float32]:
    """Renders a table: (size, size, 3) linear radiance ((.., 4) with coverage when `alpha`).

    Defaults as `experiments render`: sphere, `sun:40,30`, view (70, 0), orthographic, 256 px,
    64 spp, seed 0, the sobol sampler."""

def write_png(path: PathLike, image: ArrayLike, exposure: float = 1.0) -> None:
    """Writes a linear image as an 8-bit sRGB PNG, tonemapped as `experiments render -o`."""

def write_exr(path: PathLike, image: ArrayLike) -> None:
    """Writes a linear image as OpenEXR (coverage as alpha), as `experiments render --exr`."""

def relae(a: ArrayLike, b: ArrayLike) -> float:
    """Relative absolute error of `b` against the reference `a`: of two tables, their image
    RelAE (Fig. 7's measure: preview sphere, sun and sky, 128 px, 16 spp); of two images, of
    their pixels."""

def attributes(table: ArrayLike) -> npt.NDArray[np.float64]:
    """The 7 attributes of §5.1: [diffuse R, G, B, specular R, G, B, roughness]."""

class Model:
    """A trained DeepBRDF model (`Model.load()`: the shipped one)."""

    @staticmethod
    def load(
        path: Optional[PathLike] = None,
        *,
        refine: Optional[int] = None,
        device: Optional[str] = None,
    ) -> "Model":
        """Loads a model directory (None: the shipped model); `refine`: the refinement steps
        of each encoding (the command line's `--refine`); `device`: `flex` or `ndarray`."""
    @property
    def k(self) -> int:
        """The number of latent values."""
    @property
    def id(self) -> str:
        """The model's id."""
    @property
    def path(self) -> pathlib.Path:
        """The model directory."""
    def encode(self, table: ArrayLike) -> npt.NDArray[np.float32]:
        """Eq. (2): the latent vector (k,) of a table."""
    def encode_batch(self, tables: ArrayLike) -> npt.NDArray[np.float32]:
        """`encode` of each table of (n, 3, 90, 90, 180): (n, k)."""
    def decode(self, latent: ArrayLike) -> Table:
        """Eq. (3): the table of a latent vector (k,)."""
    def decode_batch(self, latents: ArrayLike) -> npt.NDArray[np.float32]:
        """`decode` of each row of (n, k): (n, 3, 90, 90, 180)."""
    def reconstruct(self, table: ArrayLike) -> Table:
        """Encode then decode."""
    def reconstruct_batch(self, tables: ArrayLike) -> npt.NDArray[np.float32]:
        """`reconstruct` of each table of (n, 3, 90, 90, 180)."""
    def edit(
        self,
        table: ArrayLike,
        *,
        diffuse: Optional[Sequence[float]] = None,
        diffuse_scale: Optional[float] = None,
        specular: Optional[Sequence[float]] = None,
        specular_scale: Optional[float] = None,
        roughness: Optional[float] = None,
        roughness_scale: Optional[float] = None,
        mode: Optional[str] = None,
    ) -> Table:
        """§5.1: set or scale the diffuse albedo, specular albedo or roughness, as
        `experiments edit`; `mode`: parts (default, no network), stretch, residual, paper, nearest, transfer or
        analytic."""
    def interpolate(self, a: ArrayLike, b: ArrayLike, steps: int = 9) -> npt.NDArray[np.float32]:
        """Fig. 10's latent path from `a` to `b`: (steps, 3, 90, 90, 180)."""
    def recover(self, image: Union[PathLike, ArrayLike]) -> Table:
        """§5.2: the table of the material in one photo (a path, uint8 sRGB (H, W, 3) or
        float linear (H, W, 3|4))."""
    def library_decode_seconds(self, latent: ArrayLike, repeats: int = 10) -> list[float]:
        """The library's own time of each of `repeats` decodes (the benchmark's reference)."""
