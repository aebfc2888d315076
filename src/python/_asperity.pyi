# SPDX-License-Identifier: GPL-3.0-or-later
# Type stubs of the compiled module asperity._asperity (src/python/module.cpp). Every public name of
# the module has an entry here: tests/python/test_stubs.py compares them both ways.
from os import PathLike
from typing import Any, Callable, Mapping, Optional, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
Scene = Union[str, "PathLike[str]", Mapping[str, Any]]
Progress = Optional[Callable[[int, int], Any]]

def presets() -> list[str]:
    """Names of the built-in preset scenes."""

def preset_text(name: str) -> str:
    """The TOML text of a preset scene."""

def scene_toml(scene: Scene) -> str:
    """The effective scene (path, preset name or dict) as a format-1 TOML document."""

def run(
    scene: Scene,
    progress: Progress = None,
    arrays: Optional[bool] = None,
    max_array_drops: int = 2000000,
    out: Union[None, bool, str, "PathLike[str]"] = None,
) -> dict[str, Any]:
    """Runs a scene as validate-geometry does and returns report.json as a dict.

    out: None (default) writes no file; a directory path (or True: the scene's outputs.dir) writes
    the figures and the scene's output files there."""

class RoughSphere:
    """An explicit rough sphere (core/geometry.hpp)."""
    @property
    def asperities(self) -> int: ...
    @property
    def radius(self) -> float: ...
    @property
    def asperity_radius(self) -> float: ...
    def __len__(self) -> int: ...
    @property
    def centres(self) -> FloatArray:
        """Unit asperity centres, shape (N, 3): a read-only view of the sphere's memory."""
    def query(self, backend: str = "grid") -> ContactQuery:
        """A contact query index over the centres (brute, kdtree, cgal, fcl, grid)."""

def make_rough_sphere(
    asperities: int = 100000,
    radius: float = 3e-3,
    asperity_radius: float = 6.5e-7,
    seed: int = 1,
    sphere_id: int = 0,
) -> RoughSphere:
    """N asperity centres uniform on the sphere of radius R, a pure function of (seed, sphere_id)."""

class ContactQuery:
    """A contact query index over a RoughSphere's centres (RoughSphere.query())."""
    @property
    def backend(self) -> str: ...
    @property
    def memory_bytes(self) -> int: ...
    def lowest(self, d: ArrayLike) -> dict[str, Any]:
        """The two lowest asperities for unit body-frame down directions d, shape (M, 3) or (3,)."""
    def contact(self, q: ArrayLike) -> dict[str, Any]:
        """World-frame contacts of the body rotated by unit quaternions q = (w, x, y, z), shape (M, 4)."""

def backends() -> list[str]:
    """The contact query backends this build has."""

def body_down(q: ArrayLike) -> FloatArray:
    """The world's down direction in the body frame of bodies rotated by unit quaternions (w, x, y, z)."""

class Restitution:
    """A microscopic eps_n(v) model (core/restitution.hpp)."""
    @property
    def name(self) -> str: ...
    @overload
    def __call__(self, v: float) -> float: ...
    @overload
    def __call__(self, v: ArrayLike) -> FloatArray: ...

def pade14(beta: float = 0.0467) -> Restitution:
    """Viscoelastic eps_n, Pade [1/4] of Eq. 9."""

def constant(e: float) -> Restitution:
    """eps_n = e at every speed."""

def solve_impact(
    mass: float,
    inertia: Union[float, ArrayLike],
    V: ArrayLike,
    Omega: ArrayLike,
    r: ArrayLike,
    n: ArrayLike = [0.0, 0.0, 1.0],
    eps_n: Union[float, Restitution] = 1.0,
    eps_t: float = 1.0,
) -> dict[str, Any]:
    """Impulse solve of Eq. 7 (core/impact.hpp) over arrays."""

class Law:
    """A one-dimensional law with pdf and cdf (laws/theory.hpp)."""
    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def mean(self) -> float: ...
    @overload
    def pdf(self, x: float) -> float: ...
    @overload
    def pdf(self, x: ArrayLike) -> FloatArray: ...
    @overload
    def cdf(self, x: float) -> float: ...
    @overload
    def cdf(self, x: ArrayLike) -> FloatArray: ...

def eq14_rxy(asperities: int, radius: float) -> Law:
    """Eq. 14: law of r_xy [m] (flat cap, Poisson points; Rayleigh)."""

def exact_sphere_rxy(asperities: int, radius: float) -> Law:
    """Exact finite-N law of r_xy [m] on the sphere."""

def eq18_rx(asperities: int, radius: float) -> Law:
    """Eq. 18: law of r_x [m] (Normal)."""

def exact_sphere_rx(asperities: int, radius: float) -> Law:
    """Exact finite-N law of r_x [m] on the sphere."""

def core_contact_probability(asperities: int, radius: float, asperity_radius: float) -> float:
    """The probability that a drop's contact is the core sphere rather than an asperity."""

def eq28_printed(asperities: int = 100000, radius: float = 3e-3, asperity_radius: float = 6.5e-7, speed: float = 1.3,
                 omega_x: float = 0.2, omega_y: float = 0.0, beta: float = 0.0467, core_contacts: bool = False) -> Law:
    """Eq. 28 as printed: law of eps."""

def eq28_corrected(asperities: int = 100000, radius: float = 3e-3, asperity_radius: float = 6.5e-7, speed: float = 1.3,
                   omega_x: float = 0.2, omega_y: float = 0.0, beta: float = 0.0467, core_contacts: bool = False) -> Law:
    """Eq. 28 corrected: law of eps (docs/sec4-derivations.md)."""

def eq28_paper_route(asperities: int = 100000, radius: float = 3e-3, asperity_radius: float = 6.5e-7, speed: float = 1.3,
                     omega_x: float = 0.2, omega_y: float = 0.0, beta: float = 0.0467, core_contacts: bool = False) -> Law:
    """The paper's route to Eq. 28 carried out correctly: law of eps."""

def eq33_printed(asperities: int = 100000, radius: float = 3e-3, asperity_radius: float = 6.5e-7, speed: float = 1.3,
                 omega_x: float = 0.2, omega_y: float = 0.0, beta: float = 0.0467, core_contacts: bool = False) -> Law:
    """Eq. 33 as printed: law of Omega'_x [rad/s]."""

def eq33_corrected(asperities: int = 100000, radius: float = 3e-3, asperity_radius: float = 6.5e-7, speed: float = 1.3,
                   omega_x: float = 0.2, omega_y: float = 0.0, beta: float = 0.0467, core_contacts: bool = False) -> Law:
    """Eq. 33 corrected: law of Omega'_x [rad/s]."""

def cor_table(
    scene: Scene = "fig4",
    speeds: Optional[Sequence[float]] = None,
    probabilities: Union[int, Sequence[float]] = 201,
    drops: Optional[int] = None,
    path: Union[None, str, "PathLike[str]"] = None,
    progress: Progress = None,
    spins: Optional[Sequence[float]] = None,
    omega_bands: int = 0,
) -> dict[str, Any]:
    """A restitution table for DEM codes (app/cor_table.hpp): the .json header's keys, with
    speeds_m_s, probabilities, quantiles (and spins_rad_s, omega_band_quantiles) as arrays; path
    must end in .csv (asperity.read_cor_table reads it back)."""
