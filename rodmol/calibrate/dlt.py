"""Stereo reconstruction as in the paper's section V-C: the direct linear
transformation (DLT, eq. 14) of each camera, calibrated on control points,
and the triangulation of markers seen by two or more cameras.

Eq. (14) maps a point (x, y, z) [m] of the object frame (rodmol's global
frame) to image coordinates [px]::

    u = (H1 x + H2 y + H3 z + H4) / (H9 x + H10 y + H11 z + 1)
    v = (H5 x + H6 y + H7 z + H8) / (H9 x + H10 y + H11 z + 1)

i.e. a 3x4 projection matrix with its last entry fixed to 1.
"""

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ..errors import ParameterError
from .measured import MarkerTracks, PixelTracks

#: Fewest control points that determine the 11 parameters (2 equations each).
MIN_CONTROL_POINTS = 6


@dataclass(frozen=True)
class Camera:
    """A camera as its 11 DLT parameters ``H`` (H1..H11 of eq. 14).

    ``errors`` are the reprojection errors [px] of the control points it was
    calibrated on (empty for a camera built from known parameters).
    """

    H: np.ndarray
    errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    name: str = "camera"

    @property
    def matrix(self):
        """The 3x4 projection matrix (bottom-right entry 1)."""
        return np.append(self.H, 1.0).reshape(3, 4)

    @property
    def centre(self):
        """The camera's projection centre [m], global: the point every ray passes through
        (the null vector of :attr:`matrix`); None for a camera at infinity (affine)."""
        null = np.linalg.svd(self.matrix)[2][-1]
        if abs(null[3]) <= 1e-12 * np.max(np.abs(null[:3])):
            return None
        return null[:3] / null[3]

    @property
    def rms(self):
        """Root-mean-square reprojection error [px] of the control points."""
        return float(np.sqrt(np.mean(self.errors**2))) if len(self.errors) else 0.0

    def project(self, xyz):
        """Image coordinates (..., 2) [px] of points ``xyz`` (..., 3) [m], global."""
        h = np.asarray(xyz, dtype=float) @ self.matrix[:, :3].T + self.matrix[:, 3]
        return h[..., :2] / h[..., 2:]

    @classmethod
    def looking_at(cls, position, target, focal=1500.0, centre=(620.0, 500.0), up=(0.0, 1.0, 0.0),
                   name="camera"):
        """A pinhole camera at ``position`` [m] aimed at ``target`` [m] (global),
        focal length ``focal`` [px], principal point ``centre`` [px]; the image v
        axis points along -``up`` (rows grow downward)."""
        c, forward = np.asarray(position, float), np.asarray(target, float) - np.asarray(position, float)
        z = forward / np.linalg.norm(forward)
        x = np.cross(z, up)
        if not np.linalg.norm(x) > 1e-9:
            raise ParameterError(f"camera {name!r}: `up` {up!r} is parallel to the viewing direction")
        x /= np.linalg.norm(x)
        rotation = np.array([x, np.cross(z, x), z])  # rows: image u, v and depth axes
        k = np.array([[focal, 0.0, centre[0]], [0.0, focal, centre[1]], [0.0, 0.0, 1.0]])
        p = k @ np.column_stack([rotation, -rotation @ c])
        return cls(_parameters(p), name=name)


def calibrate_dlt(xyz, uv, name="camera", refine=True):
    """Calibrate one camera's 11 DLT parameters from control points.

    Parameters
    ----------
    xyz : (n, 3) control points [m], global frame; n >= 6, not coplanar.
    uv : (n, 2) their image coordinates [px].
    refine : bool
        After the linear least-squares solution (on normalised coordinates,
        for conditioning), minimise the reprojection errors themselves.

    Returns
    -------
    Camera, with ``errors`` the reprojection error of each control point [px].
    """
    xyz, uv = np.asarray(xyz, dtype=float), np.asarray(uv, dtype=float)
    if xyz.ndim != 2 or xyz.shape[1] != 3 or uv.shape != (len(xyz), 2):
        raise ParameterError(f"camera {name!r}: control points need xyz (n, 3) and uv (n, 2), "
                             f"got {xyz.shape} and {uv.shape}")
    if len(xyz) < MIN_CONTROL_POINTS:
        raise ParameterError(f"camera {name!r}: the 11 DLT parameters need at least "
                             f"{MIN_CONTROL_POINTS} control points, got {len(xyz)}")
    if not (np.all(np.isfinite(xyz)) and np.all(np.isfinite(uv))):
        raise ParameterError(f"camera {name!r}: control points must be finite (no missing samples)")
    spread = np.linalg.svd(xyz - xyz.mean(axis=0), compute_uv=False)
    if spread[2] <= 1e-6 * spread[0]:
        raise ParameterError(f"camera {name!r}: the control points are (nearly) coplanar; "
                             "the DLT needs points spanning a volume")
    t3, t2 = _normaliser(xyz), _normaliser(uv)
    x = _homogeneous(xyz) @ t3.T
    u = _homogeneous(uv) @ t2.T
    rows = np.zeros((2 * len(x), 12))
    rows[0::2, 0:4], rows[0::2, 8:12] = x, -u[:, :1] * x
    rows[1::2, 4:8], rows[1::2, 8:12] = x, -u[:, 1:2] * x
    p = np.linalg.svd(rows)[2][-1].reshape(3, 4)
    H = _parameters(np.linalg.solve(t2, p @ t3))
    if refine:
        H = least_squares(lambda h: (Camera(h).project(xyz) - uv).ravel(), H, method="lm").x
    errors = np.linalg.norm(Camera(H).project(xyz) - uv, axis=1)
    return Camera(H, errors, name)


def triangulate(cameras, uvs):
    """3-D positions of markers seen by two or more cameras.

    Parameters
    ----------
    cameras : sequence of Camera (>= 2)
    uvs : sequence of (..., 2) image coordinates [px] (or PixelTracks), one
        per camera, all of the same shape; NaN marks an occluded sample.

    Returns
    -------
    (..., 3) positions [m], global frame, NaN where fewer than two cameras see
    the point (MarkerTracks if PixelTracks were given). Exact for exact image
    coordinates; with noise, the linear estimate is reweighted once by the
    projective depth so that it minimises (nearly) the image errors.
    """
    cameras = list(cameras)
    tracks = [u for u in uvs] if uvs is not None else []
    if len(cameras) < 2 or len(tracks) != len(cameras):
        raise ParameterError(f"triangulation needs two or more cameras and one set of image points "
                             f"per camera, got {len(cameras)} cameras and {len(tracks)} sets")
    for i, camera in enumerate(cameras):
        if not isinstance(camera, Camera):
            raise ParameterError(f"`cameras[{i}]` must be a rodmol.calibrate.dlt.Camera, got {camera!r}")
    _check_baseline(cameras)
    as_tracks = all(isinstance(u, PixelTracks) for u in tracks)
    if as_tracks and any(len(u.t) != len(tracks[0].t) or not np.allclose(u.t, tracks[0].t) for u in tracks):
        raise ParameterError("the cameras' pixel tracks must share their sample times")
    uv = np.stack([np.asarray(u.uv if isinstance(u, PixelTracks) else u, dtype=float) for u in tracks])
    if uv.shape[-1] != 2:
        raise ParameterError(f"image coordinates must end in (u, v), got shape {uv.shape[1:]}")
    seen = np.all(np.isfinite(uv), axis=-1)  # (n_cam, ...)
    a, b = _equations(cameras, np.where(seen[..., None], uv, 0.0), seen)
    xyz = _solve(a, b, np.sum(seen, axis=0) >= 2)
    found = np.all(np.isfinite(xyz), axis=-1)
    depth = np.stack([np.where(seen[i] & found, xyz @ c.H[8:11] + 1.0, 1.0) for i, c in enumerate(cameras)])
    a, b = a / np.repeat(depth, 2, axis=0)[..., None], b / np.repeat(depth, 2, axis=0)
    xyz = _solve(a, b, np.sum(seen, axis=0) >= 2)
    if as_tracks:
        return MarkerTracks(tracks[0].t, xyz, tracks[0].names)
    return xyz


def _check_baseline(cameras):
    """Refuse cameras that all sit at one centre: their rays through a marker coincide,
    so no position follows from them, however many there are."""
    centres = [c.centre for c in cameras]
    if any(c is None for c in centres):
        return  # a camera at infinity views along parallel rays: any other camera's rays cross them
    spread = max(np.linalg.norm(c - centres[0]) for c in centres)
    size = max(np.linalg.norm(c) for c in centres)
    if spread <= 1e-9 * max(size, 1.0):
        names = ", ".join(repr(c.name) for c in cameras)
        # + 0.0: a rounded -0.0 would print as '-0.0' on some BLAS builds
        raise ParameterError(f"the cameras are degenerate: {names} all have their centre at "
                             f"{tuple((np.round(centres[0], 6) + 0.0).tolist())} m (one position), so their rays "
                             "through a marker coincide and triangulation cannot find its depth; "
                             "use cameras at two different positions")


def reprojection_errors(cameras, uvs, xyz):
    """Distances [px] between image points ``uvs`` (one (..., 2) per camera) and the
    projections of ``xyz`` (..., 3): shape (n_cameras, ...), NaN where missing."""
    xyz = np.asarray(xyz.xyz if isinstance(xyz, MarkerTracks) else xyz, dtype=float)
    return np.stack([np.linalg.norm(c.project(xyz) - np.asarray(getattr(u, "uv", u), float), axis=-1)
                     for c, u in zip(cameras, uvs)])


def _equations(cameras, uv, seen):
    """Per camera two linear equations a . (x, y, z) = b in the unknown point;
    rows of unseen samples are zero. Shapes (2 n_cam, ..., 3) and (2 n_cam, ...)."""
    a, b = [], []
    for i, cam in enumerate(cameras):
        h, w = cam.H, seen[i][..., None].astype(float)
        for k, offset in ((0, 0), (1, 4)):
            coord = uv[i][..., k:k + 1]
            a.append(w * (h[offset:offset + 3] - coord * h[8:11]))
            b.append(w[..., 0] * (coord[..., 0] - h[offset + 3]))
    return np.stack(a), np.stack(b)


def _solve(a, b, ok):
    """Least-squares points from the stacked equations (normal equations per sample); NaN
    where the rays do not cross at one point (a point on the line through the cameras)."""
    ata = np.einsum("k...i,k...j->...ij", a, a)
    atb = np.einsum("k...i,k...->...i", a, b)
    ok = ok & np.all(np.isfinite(ata), axis=(-2, -1))
    ok = ok & (np.linalg.cond(np.where(ok[..., None, None], ata, np.eye(3))) < 1e12)
    ata[~ok] = np.eye(3)  # unseen samples: any regular system, overwritten with NaN below
    xyz = np.linalg.solve(ata, atb[..., None])[..., 0]
    xyz[~ok] = np.nan
    return xyz


def _parameters(p):
    """The 11 DLT parameters of a 3x4 projection matrix (scaled so p[2, 3] = 1)."""
    if abs(p[2, 3]) < 1e-12 * np.abs(p).max():
        raise ParameterError("the object frame's origin lies in the camera's focal plane; "
                             "the DLT parameters (last entry 1) cannot describe this camera")
    return (p / p[2, 3]).ravel()[:11]


def _homogeneous(points):
    return np.column_stack([points, np.ones(len(points))])


def _normaliser(points):
    """Similarity moving the points' centroid to 0 and their mean distance to sqrt(dim)."""
    dim = points.shape[1]
    centre = points.mean(axis=0)
    scale = np.sqrt(dim) / np.mean(np.linalg.norm(points - centre, axis=1))
    t = np.eye(dim + 1)
    t[:dim, :dim] *= scale
    t[:dim, dim] = -scale * centre
    return t
