"""frusta: exact, fast ray queries on triangle meshes, from numpy.

    import numpy as np, frusta
    scene = frusta.Scene(vertices, triangles)        # (n, 3) floats, (m, 3) ints
    hits = scene.intersect(origins, directions)       # arrays of shape origins.shape[:-1]
    hits.t, hits.prim, hits.u, hits.v, hits.normal    # t = inf, prim = INVALID_ID on a miss

Rays are given as origins and directions of shape (..., 3), any float dtype
(C-contiguous float32 is read in place, anything else converted once);
t is in units of the direction, which need not be normalized. tnear and
tfar are numbers or one value per ray. A NaN or infinite origin or
direction raises ValueError. Calls release the GIL and trace on all cores
(set_threads). A scene may be traced from several Python threads at once.
"""
from collections import namedtuple

from ._frusta import INVALID_ID, VERSION_MAJOR, VERSION_MINOR, get_threads, isa, save_image, set_threads
from ._frusta import Scene as _Scene

__version__ = f"{VERSION_MAJOR}.{VERSION_MINOR}"
__all__ = ["Scene", "Hits", "AllHits", "Image", "INVALID_ID", "set_threads", "get_threads", "isa", "to_srgb8", "save_image"]

Hits = namedtuple("Hits", "t prim u v normal")
Hits.__doc__ = """Closest hits: t (float32, inf on a miss), prim (uint32 triangle number,
INVALID_ID on a miss), barycentrics u, v of the 2nd and 3rd vertex, and the
unnormalized geometric normal (v1 - v0) x (v2 - v0) (zero on a miss)."""

Image = namedtuple("Image", "rgb albedo normal depth spp")
Image.__doc__ = """A rendered image: rgb (height, width, 3) float32, row 0 at the top; the
guides albedo and normal (height, width, 3) and depth (height, width; 1e30
where the camera sees nothing); spp, the samples per pixel summed."""

AllHits = namedtuple("AllHits", "ray prim t u v count")
AllHits.__doc__ = """Every crossing, flat and grouped by ray in order of t: ray (int64 index
into the rays, flattened), prim, t, u, v; count (shape of the rays) is the
number of all crossings of each ray, also those beyond max_hits."""

INF = float("inf")


def to_srgb8(image):
    """Display values in [0, 1] (an Image's rgb with display=True) as 8-bit
    sRGB, the encoding frusta render writes to PNG."""
    import numpy as np

    v = np.clip(np.nan_to_num(np.asarray(image, dtype=np.float32), nan=0.0), 0.0, 1.0)
    s = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    return (s * 255.0 + 0.5).astype(np.uint8)


class Scene(_Scene):
    """Scene(vertices, triangles, smooth=0): a triangle mesh, ready to trace.

    vertices: (n, 3) floats; triangles: (m, 3) integer vertex indices.
    C-contiguous float32 vertices are read in place: the scene holds the
    array until it is closed, and its values must not change meanwhile
    (the tree is built on them); other vertices are converted once, and
    the triangles are always copied and checked. Degenerate triangles are
    kept in the numbering but never hit.
    Scene.load(path, smooth=30) reads PLY, OBJ and the formats Assimp reads
    (also .zst-compressed); Scene.builtin() is frusta's built-in scene.
    smooth: the crease angle in degrees of the shading normals render()
    makes where the file gives none (30, as frusta render; 0: flat); tracing
    never uses them.
    """

    def intersect(self, origins, directions, tnear=0.0, tfar=INF, normals=True, reorder=False):
        """The closest hit of each ray in (tnear, tfar), as Hits.
        normals=False leaves hits.normal None, sparing that array.
        reorder=True traces many incoherent rays (random origins and
        directions) in the order of their origins' cells, which pays on large
        scenes; the answers are those of a trace mode (t and the triangle the
        same, u and v to rounding)."""
        return Hits(*self._intersect(origins, directions, tnear, tfar, normals, reorder))

    def occluded(self, origins, directions, tnear=0.0, tfar=INF, reorder=False):
        """Whether anything lies on each ray in (tnear, tfar): a bool array.
        reorder as for intersect."""
        return self._occluded(origins, directions, tnear, tfar, reorder)

    def intersect_all(self, origins, directions, max_hits=16, tnear=0.0, tfar=INF):
        """Every triangle each ray crosses in (tnear, tfar), each once (also
        through shared edges and vertices), the first max_hits per ray in
        order of t, as AllHits."""
        return AllHits(*self._intersect_all(origins, directions, max_hits, tnear, tfar))

    def count_intersections(self, origins, directions, tnear=0.0, tfar=INF):
        """How many times each ray crosses the surface in (tnear, tfar)
        (odd: it starts inside a closed, consistently wound mesh)."""
        return self._intersect_all(origins, directions, 0, tnear, tfar)[5]

    def intersect_camera(self, eye, at, up, fov, width, height, directions=False, normals=True):
        """The closest hits of a pinhole camera's rays (vertical field of view
        fov in degrees, rays through pixel centres, row 0 at the top), traced
        as multi-frusta: Hits of shape (height, width), t in units of the
        rays' normalized directions (the origin is eye). With
        directions=True, returns (hits, directions), the directions of shape
        (height, width, 3). normals=False leaves hits.normal None, sparing a
        fetch of the triangle per pixel."""
        *h, dirs = self._intersect_camera(eye, at, up, fov, width, height, directions, normals)
        return (Hits(*h), dirs) if directions else Hits(*h)

    def occluded_point_light(self, points, light, eps=None):
        """Whether each point (..., 3) is in shadow of a point light: anything
        on the segment from light to the point, leaving out its last eps
        (default: 1e-5 of the scene's diagonal, for points on surfaces).
        Traced from the light as multi-frusta, 16 consecutive points a
        frustum: order them coherently (an image's hit points row by row)."""
        if eps is None:
            lo, hi = self.bounds
            eps = 1e-5 * float(((hi - lo) ** 2).sum()) ** 0.5
        return self._occluded_point_light(points, light, eps)

    def render(self, width=None, height=None, shade=None, eye=None, at=None, up=None, fov=None, spp=None,
               light=None, environment=None, exposure=None, denoise=False, display=True, max_depth=None,
               sampler=None, seed=None, aperture=None, focus=None, env_color=None, env_intensity=None,
               env_rotate=None):
        """frusta's renderers, as `frusta render` draws. What is not given
        comes from the scene file the scene was loaded from, if any, else
        the defaults: shade is eyelight, normals, shadows, softshadow,
        whitted, ao or path (eyelight); the size (required unless the file
        gives one); the scene's own view unless eye and at are given (up
        +y, fov 50 degrees vertical); spp, samples per pixel (16; multiples
        of 16 for ao and softshadow); light, the point light of shadows,
        whitted and path. Path tracing: environment, a lat-long .hdr or
        .exr sky (else env_color, white), scaled by env_intensity and
        turned by env_rotate degrees; max_depth segments a path (13;
        whitted's depth, 4); sampler "hammersley" or "sobol" with seed
        (1); a thin lens of radius aperture focused at focus (at `at`).
        display=True gives display values (path through the filmic curve
        at exposure stops), else linear radiance; denoise=True denoises
        path, ao and softshadow. Returns an Image."""
        return Image(*self._render(width, height, shade, eye, at, up, fov, spp, light, environment, exposure,
                                   denoise, display, max_depth, sampler, seed, aperture, focus, env_color,
                                   env_intensity, env_rotate))

    def visibility_area_light(self, points, corner, e1, e2, samples=16, seed=1, eps=None):
        """The fraction of a quad light (corner + a e1 + b e2, a and b in
        [0, 1)) each point (..., 3) sees, from samples shadow rays a point (a
        multiple of 16), traced as multi-frusta: a point's 16 rays a frustum,
        16 consecutive points a batch, so give neighbours together (an
        image's hit points in 4x4 blocks). eps (default 1e-5 of the scene's
        diagonal) is left out at the point."""
        if eps is None:
            lo, hi = self.bounds
            eps = 1e-5 * float(((hi - lo) ** 2).sum()) ** 0.5
        return self._visibility_area_light(points, corner, e1, e2, samples, seed, eps)

    def contains(self, points):
        """Whether each point lies inside the closed mesh: an odd count of
        crossings along a fixed, irrational-ish direction."""
        import numpy as np

        p = np.asarray(points, dtype=np.float32)
        d = np.broadcast_to(np.array([0.5773503, 0.5773491, 0.5773517], dtype=np.float32), p.shape)
        return self.count_intersections(p, np.ascontiguousarray(d)) % 2 == 1

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self):
        try:
            return f"<frusta.Scene {self.triangle_count} triangles>"
        except ValueError:
            return "<frusta.Scene closed>"
