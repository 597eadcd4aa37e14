# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The triad: a ternary link held by three binary links from known points (one module per kind).

The class-III Assur group (RRR-RRR-RRR): a rigid ternary link with pins
``E1``, ``E2``, ``E3`` and three binary links of lengths ``l1``, ``l2``,
``l3`` from known points ``P1``, ``P2``, ``P3`` to them. Its four bodies and
six pins close at once: no dyad places any of its points alone.

Position
    With the ternary's angle ``phi`` (the direction from ``E1`` to ``E2``),
    ``R = exp(i phi)`` and ``Ei = E1 + R di`` (``di`` the pins in its frame),
    each binary says ``|E1 - (Pi - R di)| = li``: ``E1`` lies on three circles
    whose centres move with ``phi``. Subtracting the first circle's equation
    from the others leaves two equations linear in ``E1``; by Cramer's rule
    and the first circle, one equation ``G(phi) = 0`` remains, a
    trigonometric polynomial of degree 4 in ``phi`` (its top terms cancel:
    in ``z = exp(i phi)`` it is a polynomial of degree 6 where the mechanism
    is generic). Its coefficients come exactly from 16 samples of ``G`` (a
    discrete Fourier transform), its roots from the companion matrix
    (``numpy.roots``); the real ones (``|z| = 1`` within rounding) are the
    assemblies. The one kept is the nearest to the branch followed from the
    scene's written pose (below); it is polished by Newton's method on the
    three closure equations in floats until its step is below an ulp.
Branch
    The scene writes the ternary's angle at the driving crank's start (its
    pose as drawn): the nearest assembly there is the branch. When the step
    is built, the branch is followed along the crank's whole turn (forward
    and back from the start, 720 samples each way, each the nearest root to
    the last): each solve takes the root nearest that followed branch at its
    angle, so the answer is the assembly continuous from the drawn pose, with
    no iteration in the solve. Where the followed branch ends (two assemblies
    meet and leave: the group locks), the angles beyond are refused.
Velocities and accelerations
    The derivatives of ``|Ei - Pi|^2 = li^2`` are one 3x3 linear system in
    ``E1``'s velocity (or acceleration) and the ternary's rate, the matrix
    ``M`` with rows ``(ui.x, ui.y, ui . (i R di))``, ``ui = Ei - Pi``: the
    same matrix as Newton's, solved by its adjugate; each binary's rates are
    then ``ui x (vEi - vPi) / li^2`` and ``ui x (aEi - aPi) / li^2``.
Bounds and singular points
    First order, from the inputs' bounds through ``M``'s inverse (``|M^-1|``'s
    entries, computed): the group's conditioning. Its near-singularity
    measure is ``|det M|`` over the product of the rows' norms (each row
    scaled to its link's length and the ternary's size), 1 where the three
    binaries are square to the ternary's motion, 0 where they are
    concurrent or parallel with it (the group then moves with its inputs
    held: a singular point). At or below :data:`~.context.SINGULAR` the solve
    is refused in one line, as where the followed branch has no root or the
    nearest two roots are within rounding of each other.

One text (:meth:`_TriadStep._close`) serves one solve (floats) and an array
of angles (NumPy arrays, every entry at once: one batched eigenvalue solve,
Newton's steps masked where converged), with complex values as pairs
multiplied as Python multiplies complex numbers and the C library's special
functions in both: the array path gives the single-angle path's bits.
The kernel loops over roots and Newton's steps, outside the compiler's
kernel subset: the compiled paths fall back to the general solver with the
reason (:mod:`.compiler`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
import functools
import math
from typing import Any

import numpy as np

from .base import Item, Names, Placing, Reading, Step
from .context import _Context, _U4, _U7, SINGULAR
from .graph import Body, Fragment, Frame, Motion, pin, REVOLUTE, Role
from .model import _check_length, _check_name, _g, Link, SceneUnits, Where
from ..bounds import U
from ..errors import SceneError

#: Samples of the followed branch each way from the start (half a turn each).
SAMPLES = 720
#: Samples of ``G`` per turn: twice its degree and more (exact coefficients).
_FOURIER = 16
#: How far from the unit circle, relatively, a root of the polynomial is still tried.
_NEAR_CIRCLE = 1e-3
#: Newton's steps at most (each halves the digits left, from ~1e-10: three are plenty).
_NEWTON = 6


@dataclass(frozen=True)
class Triad(Item):
    """A ternary link ``link`` with pins ``pins`` held by three binary ``links`` (in pin order)."""

    kind = 'triad'

    link: str
    pins: tuple[str, str, str]
    #: The pins in the ternary's frame (origin at the first, x toward the second), m.
    local: tuple[complex, complex, complex]
    links: tuple[Link, Link, Link]
    #: The ternary's angle (rad) at the scene's start: the branch is the assembly nearest it.
    angle: float

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.link, 'a triad link name', (self, 'link'))
        counts = [len(self.pins), len(self.links), len(self.local)]  # (anything at run time)
        if counts != [3, 3, 3]:
            msg = (f'Expected triad "{self.link}" to have 3 pins and 3 links, got '
                   f'{counts[0]} and {counts[1]}')
            raise SceneError(msg, (self, 'links'))
        for pin_name in self.pins:
            _check_name(pin_name, f'a pin of triad "{self.link}"', (self, 'pins'))
        if len(set(self.pins)) != 3:
            msg = f'Expected triad "{self.link}" to have 3 different pins, got {list(self.pins)}'
            raise SceneError(msg, (self, 'pins'))
        _check_length(abs(self.local[1]), f'triad "{self.link}" length', (self, 'local'))
        side = self.local[2]
        if not math.isfinite(side.real) or not math.isfinite(side.imag) or side.imag == 0.0:
            msg = (f'Expected the third pin of triad "{self.link}" off the line of the first '
                   f'two (a ternary link), got local [{_g(side.real)}, {_g(side.imag)}] m')
            raise SceneError(msg, (self, 'local'))
        if not math.isfinite(self.angle):
            msg = f'Expected triad "{self.link}" angle to be finite, got {self.angle!r}'
            raise SceneError(msg, (self, 'angle'))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Triad:
        """Return the triad at ``where``: ``link`` (the ternary), ``links`` (three), ``angle``.

        ``link: {name, pins: [E1, E2, E3], length, local: [x, y]}``: ``length``
        is ``|E1 E2|``, ``local`` the third pin in the frame at ``E1`` with x
        toward ``E2``; ``links[i]`` runs ``from`` a known point to ``pins[i]``;
        ``angle`` is the ternary's direction ``E1 -> E2`` at the scene's start.
        """
        read.check_keys(raw, {'type', 'link', 'links', 'angle'}, where)
        body = read.get(raw, 'link', where)
        at = f'{where}.link'
        if not isinstance(body, dict):
            raise SceneError(f'{at}: expected a mapping {{name, pins, length, local}}, got '
                             f'{read.brief(body)}')
        read.check_keys(body, {'name', 'pins', 'length', 'local'}, at)
        pins = read.get(body, 'pins', at)
        if not isinstance(pins, list) or len(pins) != 3:
            raise SceneError(f'{at}.pins: expected a list of 3 point names, got '
                             f'{read.brief(pins)}')
        names = tuple(read.name({f'[{i}]': p}, f'[{i}]', f'{at}.pins') for i, p in
                      enumerate(pins))
        raw_local = read.get(body, 'local', at)
        if not isinstance(raw_local, list) or len(raw_local) != 2:
            raise SceneError(f'{at}.local: expected [x, y], got {read.brief(raw_local)}')
        x, y = (read.length({f'[{i}]': v}, f'[{i}]', f'{at}.local', positive=False)
                for i, v in enumerate(raw_local))
        base = read.length(body, 'length', at)
        three = read.links(raw, where, 3, f'to pins {", ".join(map(str, names))}')
        built: Triad = read.build(where, {'pins': 'link.pins', 'local': 'link.local'}, cls,
                                  link=read.name(body, 'name', at), pins=names,
                                  local=(0j, complex(base), complex(x, y)), links=three,
                                  angle=read.angle(raw, 'angle', where))
        return built

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none: its refusals are their messages."""
        return {}

    @property
    def key(self) -> str:
        """Return the ternary link's name."""
        return self.link

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its three pins, the ternary link and the three binary links."""
        for pin_name in self.pins:
            yield pin_name, 'point', (self, 'pins')
        yield self.link, 'link', (self, 'link')
        for link in self.links:
            yield link.name, 'link', (link, 'name')

    def prerequisites(self, names: Names) -> set[str]:
        """Return the starts of its three binary links."""
        return {names.point(link.start, f'the start of link "{link.name}"', (link, 'start'))
                for link in self.links}

    def place(self, plan: Placing) -> Step:
        """Return its step, the branch followed along the crank's turn from the written pose."""
        plan.local[self.link] = dict(zip(self.pins, self.local, strict=True))
        for link, pin_name in zip(self.links, self.pins, strict=True):
            plan.local[link.name] = {link.start: 0j, pin_name: complex(link.length)}
        return _TriadStep(self, plan)

    def lengths(self) -> tuple[float, ...]:
        """Return its three links' lengths and the ternary's sides."""
        a, b, c = self.local
        return (*(link.length for link in self.links), abs(b - a), abs(c - b), abs(a - c))

    def scaled(self, scale: Callable[[float], float]) -> Triad:
        """Return it with every length scaled."""
        a, b, c = (replace(link, length=scale(link.length)) for link in self.links)
        p, q, r = (complex(scale(z.real), scale(z.imag)) for z in self.local)
        return replace(self, links=(a, b, c), local=(p, q, r))

    def fragment(self) -> Fragment:
        """Return its part of the graph: three binaries pinned at their starts and the ternary."""
        bodies = [Body(link.name, Role.LINK, (link.start, pin_name), Frame(link.start, link.name),
                       length=link.length)
                  for link, pin_name in zip(self.links, self.pins, strict=True)]
        bodies.append(Body(self.link, Role.LINK, self.pins, Frame(self.pins[0], self.link),
                           length=abs(self.local[1])))
        joints = [pin(link.name, link.start) for link in self.links]
        joints += [pin(self.link, pin_name, on=link.name)
                   for link, pin_name in zip(self.links, self.pins, strict=True)]
        coordinates = {name: REVOLUTE for name in (*(link.name for link in self.links),
                                                   self.link)}
        motions = [Motion(link.name, link.start, pin_name)
                   for link, pin_name in zip(self.links, self.pins, strict=True)]
        motions += [Motion(self.link, self.pins[0], p) for p in self.pins[1:]]
        return Fragment(self.link, tuple(bodies), tuple(joints), coordinates, tuple(motions))

    def toggle(self) -> tuple[str, str, tuple[str, ...]] | None:
        """Return none: its measure is its group's conditioning, no transmission angle."""
        return None


class _Refused(Exception):
    """A triad that does not close or is singular at one solve (the reason, one line)."""


# --- arithmetic shared by one solve (floats) and an array's (NumPy arrays) ---------------
# Complex values are pairs (re, im) of floats or arrays, multiplied as Python multiplies
# complex numbers (NumPy's complex product may fuse its steps: other bits); every other
# operation is an IEEE operation on floats, the same bits in Python and NumPy. Special
# functions go through the C library's (math's cos, sin, atan2, remainder; hypot as
# Python's complex abs and NumPy's hypot do), the same in both paths.

def _cmul(a: Any, b: Any) -> tuple[Any, Any]:
    """Return the product of two pairs, as Python multiplies complex numbers."""
    return a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]


def _cadd(a: Any, b: Any) -> tuple[Any, Any]:
    return a[0] + b[0], a[1] + b[1]


def _csub(a: Any, b: Any) -> tuple[Any, Any]:
    return a[0] - b[0], a[1] - b[1]


def _pair(z: complex) -> tuple[float, float]:
    return z.real, z.imag


class _One:
    """The special functions and masks of one solve (floats: refusals raise)."""

    vector = False

    @staticmethod
    def hypot(x: float, y: float) -> float:
        return abs(complex(x, y))

    cos = staticmethod(math.cos)
    sin = staticmethod(math.sin)
    isfinite = staticmethod(math.isfinite)

    @staticmethod
    def where(mask: bool, x: Any, y: Any) -> Any:
        return x if mask else y

    @staticmethod
    def refuse(mask: bool, reason: Callable[[], str]) -> None:
        if mask:
            raise _Refused(reason())

    @staticmethod
    def any(mask: bool) -> bool:
        return mask

    @staticmethod
    def not_(mask: bool) -> bool:
        return not mask

    @staticmethod
    def safe(x: float, bad: bool) -> float:
        return x

    @staticmethod
    def square_norm(x: float, y: float) -> float:
        return abs(complex(x, y)) ** 2


class _Many:
    """The special functions and masks of an array's solve (refusals clear ``ok``)."""

    vector = True

    def __init__(self, n: int) -> None:
        self.ok = np.ones(n, dtype=bool)

    hypot = staticmethod(np.hypot)
    isfinite = staticmethod(np.isfinite)

    @staticmethod
    def cos(x: Any) -> Any:
        return np.array([math.cos(t) for t in x.tolist()])

    @staticmethod
    def sin(x: Any) -> Any:
        return np.array([math.sin(t) for t in x.tolist()])

    @staticmethod
    def where(mask: Any, x: Any, y: Any) -> Any:
        return np.where(mask, x, y)

    def refuse(self, mask: Any, reason: Callable[[], str]) -> None:
        self.ok &= ~mask

    @staticmethod
    def any(mask: Any) -> bool:
        return bool(mask.any())

    @staticmethod
    def not_(mask: Any) -> Any:
        return ~mask

    @staticmethod
    def safe(x: Any, bad: Any) -> Any:
        return np.where(bad, 1.0, x)

    @staticmethod
    def square_norm(x: Any, y: Any) -> Any:
        return np.array([h ** 2 for h in np.hypot(x, y).tolist()])


def _remainders(x: Any) -> Any:
    """Return ``math.remainder(x, tau)`` of each entry (IEEE's, which NumPy has not)."""
    return np.array([math.remainder(t, math.tau) for t in x.tolist()])


def _det(m: Any) -> Any:
    (a, b, c), (d, e, f), (g, h, i) = m
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


def _adjugate(m: Any, k: Any) -> Any:
    """Return the inverse of a 3x3 matrix by its adjugate, ``k`` its determinant's inverse."""
    (a, b, c), (d, e, f), (g, h, i) = m
    return [[(e * i - f * h) * k, (c * h - b * i) * k, (b * f - c * e) * k],
            [(f * g - d * i) * k, (a * i - c * g) * k, (c * d - a * f) * k],
            [(d * h - e * g) * k, (b * g - a * h) * k, (a * e - b * d) * k]]


def _times(m: Any, x: Any) -> tuple[Any, Any, Any]:
    """Return ``m x`` for a 3x3 matrix and a 3-vector (sums left to right)."""
    return tuple(row[0] * x[0] + row[1] * x[1] + row[2] * x[2] for row in m)


def _g_samples(p2: complex, p3: complex, d2: complex, d3: complex, l1: float, l2: float,
               l3: float, z: Any) -> Any:
    """Return ``G(phi)`` at ``z = exp(i phi)`` (arrays): zero where the three circles meet.

    Relative to ``P1`` (``p2``, ``p3`` the other starts less it): the centres
    ``Qi = Pi - z di``, the linear equations ``2 Qi . E1 = |Qi|^2 - li^2 + l1^2``
    and the first circle ``|E1| = l1``, by Cramer's rule without division.
    """
    q2, q3 = p2 - z * d2, p3 - z * d3
    k2 = q2.real * q2.real + q2.imag * q2.imag - l2 * l2 + l1 * l1
    k3 = q3.real * q3.real + q3.imag * q3.imag - l3 * l3 + l1 * l1
    det = q2.real * q3.imag - q3.real * q2.imag
    nx = k2 * q3.imag - k3 * q2.imag
    ny = q2.real * k3 - q3.real * k2
    return nx * nx + ny * ny - 4.0 * l1 * l1 * det * det


_UNIT = np.exp(2j * np.pi * np.arange(_FOURIER) / _FOURIER)
#: The discrete Fourier transform taking 16 samples of G to its coefficients of
#: exp(i k phi), k = 3, 2, ..., -3 (a polynomial in z of degree 6, highest power first),
#: and those of k = 4 and -4 (zero in exact arithmetic: checked, not assumed).
_DFT = np.exp(-1j * np.outer(np.arange(3, -4, -1), 2 * np.pi * np.arange(_FOURIER) / _FOURIER)
              ) / _FOURIER
_DFT_TOP = np.exp(-1j * np.outer([4, -4], 2 * np.pi * np.arange(_FOURIER) / _FOURIER)) / _FOURIER


def _root_angles(p2: Any, p3: Any, d2: complex, d3: complex, l1: float, l2: float,
                 l3: float) -> Any:
    """Return, per row of starts, the ternary's angles where the group closes (NaN: none).

    ``p2``, ``p3``: arrays (n,) of the second and third starts less the first.
    An array (n, 6): the roots of the degree-6 polynomial in ``z = exp(i phi)``
    (companion matrices, one eigenvalue solve for all rows) that lie on the
    unit circle within :data:`_NEAR_CIRCLE`, as angles; the others NaN. A row
    whose degree-4 terms do not cancel to rounding, or whose polynomial has
    no leading term, has NaN only (no position is answered from it).
    """
    values = _g_samples(p2[:, None], p3[:, None], d2, d3, l1, l2, l3, _UNIT[None, :]).real
    coefficients = values @ _DFT.T            # (n, 7), highest power first
    top = np.abs(values @ _DFT_TOP.T).max(axis=1)
    scale = np.abs(coefficients).max(axis=1)
    lead = coefficients[:, 0]
    good = (top <= 64 * U * scale) & (np.abs(lead) > 64 * U * scale) & np.isfinite(scale)
    n = p2.shape[0]
    companion = np.zeros((n, 6, 6), dtype=np.complex128)
    safe = np.where(good, lead, 1.0)
    companion[:, 0, :] = -coefficients[:, 1:] / safe[:, None]
    companion[:, np.arange(1, 6), np.arange(5)] = 1.0
    companion[~good] = np.eye(6)
    roots = np.linalg.eigvals(companion)
    near = (np.abs(np.abs(roots) - 1.0) < _NEAR_CIRCLE) & good[:, None]
    return np.where(near, np.angle(roots), np.nan)


def _mul(a: list[Any], b: list[Any]) -> list[Any]:
    """Return the product of two Laurent polynomials of pairs centred on their middle entries."""
    out: list[Any] = [None] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            term = _cmul(x, y)
            out[i + j] = term if out[i + j] is None else _cadd(out[i + j], term)
    return out


def _coefficients(ops: Any, p2: Any, p3: Any, d2: complex, d3: complex, l1: float,
                  l2: float, l3: float) -> list[Any]:
    """Return G's coefficients of ``z**k``, k = 4 .. -4 (pairs), as its formula multiplies out.

    ``G`` of :func:`_g_samples` with ``conj(z) = 1 / z``: each centre's parts and
    its ``k`` are Laurent polynomials of degree 1, the numerators and the
    determinant of degree 2. ``p2``, ``p3``: pairs of floats (one solve) or
    of arrays (every row at once: the same bits per row).
    """
    def parts(a: Any, b: complex) -> tuple[list[Any], list[Any]]:
        # q = a + b z: its real and imaginary parts on the unit circle (z^-1, z^0, z^1).
        cb = b.conjugate()
        real = [_pair(0.5 * cb), (0.5 * (a[0] + a[0]), 0.5 * (a[1] - a[1])), _pair(0.5 * b)]
        imag = [_pair(0.5j * cb), (0.5 * (a[1] + a[1]), -0.5 * (a[0] - a[0])), _pair(-0.5j * b)]
        return real, imag

    def k_of(a: Any, b: complex, c: float) -> list[Any]:
        middle = ops.square_norm(a[0], a[1]) + abs(b) ** 2 + c
        return [_cmul(a, _pair(b.conjugate())), (middle, 0.0 * middle),
                _cmul(_pair(b), (a[0], -a[1]))]

    def minus(x: list[Any], y: list[Any]) -> list[Any]:
        return [_csub(s, t) for s, t in zip(x, y, strict=True)]

    q2r, q2i = parts(p2, -d2)
    q3r, q3i = parts(p3, -d3)
    k2 = k_of(p2, -d2, l1 * l1 - l2 * l2)
    k3 = k_of(p3, -d3, l1 * l1 - l3 * l3)
    nx = minus(_mul(k2, q3i), _mul(k3, q2i))
    ny = minus(_mul(q2r, k3), _mul(q3r, k2))
    det = minus(_mul(q2r, q3i), _mul(q3r, q2i))
    dd = _mul(det, det)
    f = -4.0 * l1 * l1
    g = [_cadd(_cadd(x, y), (f * z[0], f * z[1]))
         for x, y, z in zip(_mul(nx, nx), _mul(ny, ny), dd, strict=True)]
    return g[::-1]


def _angles(p2: complex, p3: complex, d2: complex, d3: complex, l1: float, l2: float,
            l3: float) -> list[float]:
    """Return the ternary's angles where the group closes, for one row of starts.

    As :func:`_root_angles` for one row, its coefficients multiplied out in
    floats (:func:`_coefficients`) rather than sampled; :func:`_angles_many`
    gives the same bits for every row of an array.
    """
    g = [complex(*x) for x in _coefficients(_One, _pair(p2), _pair(p3), d2, d3, l1, l2, l3)]
    scale = max(abs(x) for x in g)
    top = max(abs(g[0]), abs(g[-1]))
    lead = g[1]
    if not (math.isfinite(scale) and top <= 64 * U * scale and abs(lead) > 64 * U * scale):
        return []
    companion = np.zeros((6, 6), dtype=np.complex128)
    companion[0, :] = [-x / lead for x in g[2:-1]]
    companion[_BELOW] = 1.0
    roots = np.linalg.eigvals(companion).tolist()
    return [math.atan2(r.imag, r.real) for r in roots if abs(abs(r) - 1.0) < _NEAR_CIRCLE]


def _quotient(a: Any, b: Any) -> tuple[Any, Any]:
    """Return ``a / b`` of pairs of arrays as Python divides complex numbers (``b`` not 0)."""
    by_real = abs(b[0]) >= abs(b[1])
    ratio = np.where(by_real, b[1] / b[0], b[0] / b[1])
    denom = np.where(by_real, b[0] + b[1] * ratio, b[0] * ratio + b[1])
    re = np.where(by_real, a[0] + a[1] * ratio, a[0] * ratio + a[1]) / denom
    im = np.where(by_real, a[1] - a[0] * ratio, a[1] * ratio - a[0]) / denom
    return re, im


def _angles_many(p2: Any, p3: Any, d2: complex, d3: complex, l1: float, l2: float,
                 l3: float) -> Any:
    """Return :func:`_angles` of every row as an array (n, 6), NaN where a root is not kept.

    One companion matrix per row, one eigenvalue solve for all (each
    matrix's roots the same bits as alone); a row whose polynomial fails
    :func:`_angles`'s checks has NaN only.
    """
    g = _coefficients(_Many, _pair(p2), _pair(p3), d2, d3, l1, l2, l3)
    sizes = [np.hypot(*x) for x in g]
    scale = functools.reduce(np.maximum, sizes)
    top = np.maximum(sizes[0], sizes[-1])
    lead = g[1]
    good = np.isfinite(scale) & (top <= 64 * U * scale) & (sizes[1] > 64 * U * scale)
    safe = (np.where(good, lead[0], 1.0), np.where(good, lead[1], 0.0))
    n = p2.shape[0]
    companion = np.zeros((n, 6, 6), dtype=np.complex128)
    for j, x in enumerate(g[2:-1]):
        re, im = _quotient((-x[0], -x[1]), safe)
        companion[:, 0, j].real = re
        companion[:, 0, j].imag = im
    companion[:, _BELOW[0], _BELOW[1]] = 1.0
    companion[~good] = np.eye(6)
    roots = np.linalg.eigvals(companion)
    near = (np.abs(np.hypot(roots.real, roots.imag) - 1.0) < _NEAR_CIRCLE) & good[:, None]
    out = np.full(near.shape, np.nan)
    out[near] = [math.atan2(y, x) for x, y in zip(roots.real[near].tolist(),
                                                  roots.imag[near].tolist(), strict=True)]
    return out


_BELOW = (np.arange(1, 6), np.arange(5))


def _wrap(x: float) -> float:
    return math.remainder(x, math.tau)


class _Nearest:
    """The distance of an angle from ``guess`` modulo a turn (a sort key)."""

    def __init__(self, guess: float) -> None:
        self.guess = guess

    def __call__(self, angle: float) -> float:
        return abs(_wrap(angle - self.guess))


class _TriadStep(Step):

    def __init__(self, triad: Triad, plan: Placing) -> None:
        self.dyad = triad
        self.label = f'triad {triad.link}'
        self.key = triad.link
        self.link = triad.link
        self.pins = triad.pins
        self.starts = tuple(link.start for link in triad.links)
        self.names = tuple(link.name for link in triad.links)
        self.lengths = tuple(link.length for link in triad.links)
        self.d = triad.local
        self.size = max(abs(z) for z in triad.local)
        self.uses = self.starts
        self.defines = (*triad.pins, triad.link, *self.names)
        self.new_points = triad.pins
        self.table = self._follow(plan, triad)

    # --- the branch, followed once -------------------------------------------------

    def _follow(self, plan: Placing, triad: Triad) -> tuple[float, float, Any]:
        """Return (start angle, sample step, the ternary's angle per sample: NaN beyond)."""
        scene = plan.scene
        crank = getattr(scene, 'input', None)
        if crank is None or len(scene.drivers) != 1:
            msg = (f'Expected triad "{triad.link}" in a scene driven by one crank (its branch '
                   f"is followed along the crank's turn), got {len(scene.drivers)} drivers")
            raise SceneError(msg, (triad, 'link'))
        trace = plan.trace
        assert trace is not None  # (the plan compiler lends it)
        start = crank.start
        h = math.pi / SAMPLES
        thetas = start + h * np.arange(-SAMPLES, SAMPLES + 1)
        ctx = trace(thetas)
        p = [np.broadcast_to(ctx.points[name][0], thetas.shape) for name in self.starts]
        n = len(thetas)
        l1, l2, l3 = self.lengths
        with np.errstate(all='ignore'):
            rel2, rel3 = p[1] - p[0], p[2] - p[0]
            finite = np.isfinite(rel2) & np.isfinite(rel3)
            every = _root_angles(np.where(finite, rel2, 0), np.where(finite, rel3, 0),
                                 self.d[1], self.d[2], l1, l2, l3)
        every[~finite] = np.nan
        table = np.full(n, np.nan)
        mid = SAMPLES
        roots = [float(x) for x in every[mid] if x == x]
        if not roots:
            msg = (f'Expected triad "{triad.link}" to assemble at the scene\'s start, got no '
                   f'position where its three links reach its pins')
            raise SceneError(msg, (triad, 'link'))
        best = min(roots, key=_Nearest(triad.angle))
        table[mid] = triad.angle + _wrap(best - triad.angle)
        rows = [[x for x in row if x == x] for row in every.tolist()]
        for way in (1, -1):
            last, slope = float(table[mid]), 0.0
            k = mid + way
            while 0 <= k < n and rows[k]:
                guess = last + slope
                near = min(rows[k], key=_Nearest(guess))
                if abs(_wrap(near - guess)) > 0.25:  # the followed assembly is gone
                    break
                step = _wrap(near - last)
                table[k] = last + step
                last, slope = last + step, step
                k += way
        return start, h, table

    def followed(self, angle: float) -> float:
        """Return the followed branch's angle of the ternary at a crank angle (NaN: none)."""
        start, h, table = self.table
        t = (_wrap(angle - start) + math.pi) / h
        k = min(int(t), len(table) - 2)
        f = t - k
        a, b = table[k], table[k + 1]
        return float(a + f * (b - a))

    def _followed_many(self, angles: Any) -> Any:
        """Return :meth:`followed` at every crank angle of an array (the same bits)."""
        start, h, table = self.table
        t = (_remainders(angles - start) + math.pi) / h
        k = np.minimum(t.astype(np.int64), len(table) - 2)
        f = t - k
        a, b = table[k], table[k + 1]
        return a + f * (b - a)

    # --- one solve -------------------------------------------------------------------

    def solve_one(self, angle: float, p: tuple[complex, ...], v: tuple[complex, ...],
                  a: tuple[complex, ...], ep: tuple[float, ...], ev: tuple[float, ...],
                  ea: tuple[float, ...]) -> tuple[Any, ...]:
        """Return the pins' and links' values with bounds at one crank angle, or refuse."""
        l1, l2, l3 = self.lengths
        d = self.d
        p1 = p[0]
        guess = self.followed(angle)
        if not math.isfinite(guess):
            raise _Refused('its branch followed from the start pose ends before this crank '
                           'angle (the group cannot move on from its drawn assembly)')
        roots = _angles(p[1] - p1, p[2] - p1, d[1], d[2], l1, l2, l3)
        if not roots:
            raise _Refused('its three links cannot reach its pins (no assembly)')
        gaps = sorted((abs(_wrap(r - guess)), r) for r in roots)
        phi = gaps[0][1]
        if len(gaps) > 1 and gaps[1][0] - gaps[0][0] < 1e-9:
            raise _Refused(f'two assemblies are within rounding of each other at ternary angle '
                           f'{phi:.6g} rad (a singular point: two branches meet)')
        points, ternary, links, measure = self._close(
            _One, phi, [_pair(z) for z in p], [_pair(z) for z in v], [_pair(z) for z in a],
            ep, ev, ea)
        points = [(complex(*x), complex(*y), complex(*z), *rest) for x, y, z, *rest in points]
        links = [(complex(*x), *rest) for x, *rest in links]
        return points, (complex(*ternary[0]), *ternary[1:]), links, measure

    def solve_many(self, angles: Any, p: list[Any], v: list[Any], a: list[Any], ep: list[Any],
                   ev: list[Any], ea: list[Any]) -> tuple[Any, ...]:
        """Return :meth:`solve_one` at every entry of arrays (n,) at once: ``ok`` and pairs.

        The same operations entry by entry, so the same bits; where ``ok`` is
        false the entry is refused (its values are not answers).
        """
        ops = _Many(angles.shape[0])
        guess = self._followed_many(angles)
        ops.refuse(~np.isfinite(guess), str)
        every = _angles_many(p[1] - p[0], p[2] - p[0], self.d[1], self.d[2], *self.lengths)
        gaps = np.abs(_remainders((every - guess[:, None]).ravel())).reshape(every.shape)
        gaps[np.isnan(gaps)] = np.inf
        count = np.isfinite(every).sum(axis=1)
        ops.refuse(count == 0, str)
        nearest = np.sort(gaps, axis=1)
        ops.refuse((count > 1) & (nearest[:, 1] - nearest[:, 0] < 1e-9), str)
        phi = every[np.arange(every.shape[0]), np.argmin(gaps, axis=1)]
        phi = np.where(ops.ok, phi, 0.0)
        out = self._close(ops, phi, [_pair(z) for z in p], [_pair(z) for z in v],
                          [_pair(z) for z in a], ep, ev, ea)
        return ops.ok, out

    def _close(self, ops: Any, phi: Any, p: list[Any], v: list[Any], a: list[Any],
               ep: Any, ev: Any, ea: Any) -> tuple[Any, ...]:
        """Return the pose polished from ``phi``, its rates and bounds (pairs), or refuse.

        ``ops``: :class:`_One` (floats) or :class:`_Many` (arrays, refusals in
        its ``ok``): one text for both paths, so the same bits.
        """
        d = [_pair(z) for z in self.d]
        lens = self.lengths
        size = self.size
        # Newton on the closure |E1 + R di - Pi|^2 = li^2, unknowns E1 (x, y) and phi.
        r = (ops.cos(phi), ops.sin(phi))
        e1 = self._start_point(ops, p, r)
        active = ops.ok.copy() if ops.vector else True
        i_r = (0.0, 1.0)
        for _ in range(_NEWTON):
            u = [_csub(_cadd(e1, _cmul(r, d[i])), p[i]) for i in range(3)]
            t = [_cmul(_cmul(i_r, r), d[i]) for i in range(3)]
            f = [0.5 * (u[i][0] * u[i][0] + u[i][1] * u[i][1] - lens[i] * lens[i])
                 for i in range(3)]
            m = [(u[i][0], u[i][1], u[i][0] * t[i][0] + u[i][1] * t[i][1]) for i in range(3)]
            det = _det(m)
            bad = (det == 0.0) | ops.not_(ops.isfinite(det))
            ops.refuse(active & bad, lambda: 'its links are concurrent or parallel with the '
                       "ternary's motion (singular: its Jacobian is not invertible)")
            active = active & ops.not_(bad)
            dx, dy, dphi = (-x for x in _times(_adjugate(m, 1.0 / ops.safe(det, bad)), f))
            e1 = (ops.where(active, e1[0] + dx, e1[0]), ops.where(active, e1[1] + dy, e1[1]))
            phi = ops.where(active, phi + dphi, phi)
            r = (ops.cos(phi), ops.sin(phi))
            tiny = 4 * U * (abs(e1[0]) + abs(e1[1]) + size)
            active = active & ops.not_(abs(dx) + abs(dy) + abs(dphi) * size <= tiny)
            if not ops.any(active):
                break
        pins = [_cadd(e1, _cmul(r, d[i])) for i in range(3)]
        u = [_csub(pins[i], p[i]) for i in range(3)]
        t = [_cmul(_cmul(i_r, r), d[i]) for i in range(3)]
        m = [(u[i][0], u[i][1], u[i][0] * t[i][0] + u[i][1] * t[i][1]) for i in range(3)]
        # The measure: |det M| over the rows' norms, each row scaled to its link and the
        # ternary's size (Hadamard's ratio: 1 at best, 0 at a singular point).
        rows = [ops.hypot(m[i][0], m[i][1]) * ops.hypot(1.0, m[i][2] / (lens[i] * size))
                for i in range(3)]
        det = _det(m)
        measure = abs(det / (size * rows[0] * rows[1] * rows[2]))
        bad = (det == 0.0) | ops.not_(ops.isfinite(det)) | ops.not_(measure > SINGULAR)
        ops.refuse(bad, lambda: f"its links are concurrent or parallel with the ternary's "
                   f'motion (singular): expected its conditioning measure > {SINGULAR:g}, '
                   f'got {measure:.3g}')
        minv = _adjugate(m, 1.0 / ops.safe(det, bad))
        # Velocities: M (vE1, omega) = (ui . vPi); accelerations likewise (see module).
        b = [u[i][0] * v[i][0] + u[i][1] * v[i][1] for i in range(3)]
        vx, vy, om = _times(minv, b)
        vpins = [(vx + om * t[i][0], vy + om * t[i][1]) for i in range(3)]
        rel = [_csub(vpins[i], v[i]) for i in range(3)]
        rd = [_cmul(r, d[i]) for i in range(3)]
        c = [u[i][0] * a[i][0] + u[i][1] * a[i][1]
             - (rel[i][0] * rel[i][0] + rel[i][1] * rel[i][1])
             + om * om * (u[i][0] * rd[i][0] + u[i][1] * rd[i][1])
             for i in range(3)]
        ax, ay, al = _times(minv, c)
        spun = [_cmul((om * om * r[0], om * om * r[1]), d[i]) for i in range(3)]
        apins = [(ax + al * t[i][0] - spun[i][0], ay + al * t[i][1] - spun[i][1])
                 for i in range(3)]
        w = [(u[i][0] * rel[i][1] - u[i][1] * rel[i][0]) / (lens[i] * lens[i])
             for i in range(3)]
        arel = [_csub(apins[i], a[i]) for i in range(3)]
        alpha = [(u[i][0] * arel[i][1] - u[i][1] * arel[i][0]) / (lens[i] * lens[i])
                 for i in range(3)]
        # Bounds, first order: the closure's right sides move by li (ep_i + U li) and the
        # rounding; (E1, phi) by |M^-1| times that. Velocities and accelerations: the
        # right sides' bounds and the matrix's (|u| moves by the pins' bound) times the
        # solution, through |M^-1| again.
        amin = [[abs(x) for x in row] for row in minv]
        # The closure's residual at the polished pose, measured (a posteriori), with its
        # own rounding: (E1, phi) is within M^-1 of it and of the starts' bounds.
        dpos = [lens[i] * ep[i] + abs(0.5 * (u[i][0] * u[i][0] + u[i][1] * u[i][1]
                                             - lens[i] * lens[i]))
                + _U4 * lens[i] * lens[i] for i in range(3)]
        ex, ey, ephi = _times(amin, dpos)
        # Norms by the C library's hypot (Python's complex abs, NumPy's hypot: the same bits).
        ad = [abs(z) for z in self.d]
        epin = [ops.hypot(ex, ey) + ephi * ad[i] + U * ops.hypot(*pins[i]) + _U4 * ad[i]
                for i in range(3)]
        eu = [epin[i] + ep[i] for i in range(3)]
        # The velocity system's rows move by |du| (and u . t by |du| |d| + l |d| dphi), its
        # right sides u . vP by |du| |vP| + l |dvP|: through |M^-1| with the solution.
        aom = abs(om)
        speed = ops.hypot(vx, vy)
        grow_v = [ops.hypot(*v[i]) + speed + aom * ad[i] for i in range(3)]
        dvel = [lens[i] * ev[i] + eu[i] * grow_v[i] + lens[i] * ad[i] * aom * ephi
                + _U7 * lens[i] * grow_v[i] for i in range(3)]
        evx, evy, eom = _times(amin, dvel)
        evpin = [ops.hypot(evx, evy) + eom * ad[i] + aom * ad[i] * ephi for i in range(3)]
        # Likewise the acceleration system, whose right side also holds -|vE - vP|^2 and
        # omega^2 u . (R d).
        accel = ops.hypot(ax, ay)
        aal = abs(al)
        grow_a = [ops.hypot(*a[i]) + accel + (aal + om * om) * ad[i] for i in range(3)]
        relv = [ops.hypot(*rel[i]) for i in range(3)]
        dacc = [lens[i] * ea[i] + eu[i] * grow_a[i] + lens[i] * ad[i] * (aal + om * om) * ephi
                + 2.0 * relv[i] * (evpin[i] + ev[i]) + 2.0 * aom * eom * lens[i] * ad[i]
                + _U7 * (lens[i] * grow_a[i] + relv[i] * relv[i]) for i in range(3)]
        eax, eay, eal = _times(amin, dacc)
        eapin = [ops.hypot(eax, eay) + (eal + 2.0 * aom * eom) * ad[i]
                 + (aal + om * om) * ad[i] * ephi for i in range(3)]
        links = []
        for i in range(3):
            inv_l = 1.0 / lens[i]
            e_dir = eu[i] / lens[i] + _U7
            e_w = (evpin[i] + ev[i]) / lens[i] + abs(w[i]) * e_dir + _U4 * abs(w[i])
            e_al = (eapin[i] + ea[i]) / lens[i] + abs(alpha[i]) * e_dir + _U4 * abs(alpha[i])
            links.append(((u[i][0] * inv_l, u[i][1] * inv_l), w[i], alpha[i], e_dir, e_w, e_al))
        ternary = (r, om, al, ephi + _U4, eom, eal)
        points = [(pins[i], vpins[i], apins[i], epin[i], evpin[i], eapin[i]) for i in range(3)]
        return points, ternary, links, measure

    def _start_point(self, ops: Any, p: list[Any], r: Any) -> tuple[Any, Any]:
        """Return ``E1`` from the two linear equations of the circles at ``R = r`` (Cramer)."""
        l1, l2, l3 = self.lengths
        p1 = p[0]
        q2 = _csub(_csub(p[1], p1), _cmul(r, _pair(self.d[1])))
        q3 = _csub(_csub(p[2], p1), _cmul(r, _pair(self.d[2])))
        k2 = ops.square_norm(*q2) - l2 * l2 + l1 * l1
        k3 = ops.square_norm(*q3) - l3 * l3 + l1 * l1
        det = 2.0 * (q2[0] * q3[1] - q3[0] * q2[1])
        flat = det == 0.0
        if not ops.vector and flat:
            return p1[0] + l1, p1[1]
        det = ops.safe(det, flat)
        x = p1[0] + (k2 * q3[1] - k3 * q2[1]) / det
        y = p1[1] + (q2[0] * k3 - q3[0] * k2) / det
        return ops.where(flat, p1[0] + l1, x), ops.where(flat, p1[1], y)

    def run(self, ctx: _Context) -> None:
        starts = [ctx.points[name] for name in self.starts]
        if not ctx.vector:
            try:
                out = self.solve_one(ctx.angle, *(tuple(s[k] for s in starts) for k in range(6)))
            except _Refused as refused:
                reason = str(refused)
                ctx.check(False, self.label, lambda: reason)
                return
            self._put(ctx, *out)
            return
        shape = np.shape(ctx.angle)
        angles = np.asarray(np.broadcast_to(ctx.angle, shape), dtype=np.float64).ravel()
        columns = [[np.asarray(np.broadcast_to(s[k], shape),
                               dtype=np.complex128 if k < 3 else np.float64).ravel()
                    for s in starts] for k in range(6)]
        with np.errstate(all='ignore'):
            ok, (points, ternary, links, measure) = self.solve_many(angles, *columns)
        ctx.mask(ok.reshape(shape), self.label)

        def complexes(x: Any) -> Any:
            z = np.empty(shape, dtype=np.complex128)
            z.real = np.where(ok, x[0], math.nan).reshape(shape)
            z.imag = np.where(ok, x[1], math.nan).reshape(shape)
            return z

        def floats(x: Any) -> Any:
            return np.where(ok, x, math.nan).reshape(shape)

        for name, value in zip(self.pins, points, strict=True):
            ctx.points[name] = (*(complexes(x) for x in value[:3]),
                                *(floats(x) for x in value[3:]))
        for name, value in zip(self.names, links, strict=True):
            ctx.links[name] = (complexes(value[0]), *(floats(x) for x in value[1:]))
        ctx.links[self.link] = (complexes(ternary[0]), *(floats(x) for x in ternary[1:]))
        ctx.measures[self.key] = floats(measure)

    def _put(self, ctx: _Context, points: Any, ternary: Any, links: Any, measure: float) -> None:
        for name, value in zip(self.pins, points, strict=True):
            ctx.points[name] = value
        for name, value in zip(self.names, links, strict=True):
            ctx.links[name] = value
        ctx.links[self.link] = ternary
        ctx.measures[self.key] = measure
