# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Answers printed in the textbooks behind the shipped scenes, for golden tests.

Each entry of ``TEXTBOOK_ANSWERS`` is a dict:

``scene``
    Scene name (``config/scenes/<scene>.yaml``); evaluate at the scene's own
    crank angle, speed and acceleration.
``source``
    Seed file of the course notes, problem name, and the book where known.
``quantity``
    What the book calls the value, and what it means.
``accessor``
    How to get the same quantity from ``mk.solve(...).as_dict()``; see
    :func:`evaluate`.  One of

    - ``('joint', NAME, FIELD, 'abs' | 'signed')``: ``joints[NAME][FIELD]``;
    - ``('point', NAME, FIELD, 'norm')``: length of ``points[NAME][FIELD]``;
    - ``('product', FACTOR, ((NAME, FIELD, POWER), ...))``:
      ``FACTOR * prod(abs(joints[NAME][FIELD]) ** POWER)``, e.g.
      ``omega**2 * length`` (radial acceleration),
      ``abs(omega) * length`` (relative velocity),
      ``abs(alpha) * s`` (tangential acceleration of a slot point at ``s``),
      ``2 * abs(omega * ds/dt)`` (Coriolis), ``180/pi * angle`` (degrees).

    FIELD is ``'position'``, ``'velocity'`` or ``'acceleration'``.
``printed``
    The printed value converted to SI (m, m/s, m/s^2, rad/s, rad/s^2; degrees
    only where the quantity says so); ``unit`` names it.
``rel_tol``
    Relative tolerance the printed number deserves, measured against the
    solver's value as in the reference JSON files (``rel_diff`` there is
    ``(printed - exact) / exact``): the check is
    ``abs(got - printed) <= rel_tol * abs(got)``, see :func:`within_tolerance`.
    ``REL_COMPUTED`` for
    numbers the text computes from the data (wider where it prints fewer
    digits), ``REL_MEASURED`` for values measured on a drawing or derived
    linearly from one, ``REL_MEASURED_SQUARED`` for squares, products or ratios
    of measured values.  Wider still if ``discrepancy`` is true.
``kind``
    ``'computed'``, ``'measured'`` or ``'derived from measured'``.

Optional keys: ``exact`` (value of the same quantity for the scene as
written; given for the reference scenes and for every discrepancy),
``discrepancy`` (True: the source's number is known to be off; do not test
it tightly), ``note``.

Scenes ``whitworth``, ``offset_slider_crank`` and ``six_link_slider`` have no
printed answers here: their geometry is not a book's (see their
descriptions).
"""

import math

__all__ = ['TEXTBOOK_ANSWERS', 'evaluate', 'within_tolerance', 'REL_COMPUTED',
           'REL_MEASURED', 'REL_MEASURED_SQUARED']

REL_COMPUTED = 0.005          # number computed in the text from the data
REL_MEASURED = 0.05           # number measured on a drawing
REL_MEASURED_SQUARED = 0.10   # square, product or ratio of measured numbers


def evaluate(accessor, state):
    """Return the quantity ``accessor`` names from ``state`` (an ``as_dict()``)."""
    kind = accessor[0]
    if kind == 'joint':
        _, name, field, mode = accessor
        value = state['joints'][name][field]
        if mode == 'abs':
            return abs(value)
        if mode == 'signed':
            return value
        msg = f'Expected joint mode "abs" or "signed", got {mode!r}'
        raise ValueError(msg)
    if kind == 'point':
        _, name, field, mode = accessor
        if mode != 'norm':
            msg = f'Expected point mode "norm", got {mode!r}'
            raise ValueError(msg)
        x, y = state['points'][name][field]
        return math.hypot(x, y)
    if kind == 'product':
        _, factor, terms = accessor
        value = factor
        for name, field, power in terms:
            value *= abs(state['joints'][name][field]) ** power
        return value
    msg = f'Expected accessor kind "joint", "point" or "product", got {kind!r}'
    raise ValueError(msg)


def within_tolerance(entry, got):
    """Return True if the solver's value ``got`` matches ``entry['printed']``."""
    return abs(got - entry['printed']) <= entry['rel_tol'] * abs(got)


_KHURMI_8_10 = ('seed 000 (MDP 234 Lecture 4), "Example": crank and slotted lever '
                'quick return; Khurmi & Gupta, Theory of Machines, Example 8.10, Fig. 8.28')
_GENEVA = ('seed 000 (MDP 234 Lecture 4), "Sample Problem": Geneva mechanism; '
           'Beer & Johnston, Vector Mechanics for Engineers: Dynamics, Sample Problem 15.9 '
           '(9th ed.; numbering varies by edition)')
_PISTON = ('seed 001 (Q&A page on acceleration diagrams), "Example-1": piston, connecting '
           "rod and crank, 300 rad/s (wording of D.J. Dunn's acceleration-diagram tutorial, "
           'as far as known)')
_ROCKING = ('seed 001 (Q&A page on acceleration diagrams), "Example-2": rocking lever '
            "(wording of D.J. Dunn's acceleration-diagram tutorial, as far as known)")
_PROBLEM_3 = ('seed 002 (VIT BMEE207L Module 2), "Problem 3": four-link mechanism with '
              'points E, F, G (figure after S.S. Rattan, Theory of Machines)')
_FOUR_BAR = ('seed 002 (VIT BMEE207L Module 2), "Four Bar Mechanism": AD = 150, AB = 40 at '
             '120 rpm CW, BC = 150, CD = 80, BAD = 60 deg (Khurmi & Gupta, Theory of Machines)')
_STEAM = ('seed 002 (VIT BMEE207L Module 2), "Single Slider Crank Mechanism": theoretical '
          'steam engine, crank 0.5 m, rod 2 m, 180 rpm CW, 45 deg past IDC '
          '(Khurmi & Gupta, Theory of Machines)')
_SLIDER = ('seed 000 (MDP 234 Lecture 4), "Accelerations in a Slider-crank Linkage": crank '
           '150 mm, rod 600 mm, 300 rpm CW, 45 deg from IDC (Khurmi & Gupta, Theory of '
           'Machines); the answers are not in the notes but quoted from the book on public '
           'Q&A pages')
_UNRELIABLE = ("the source's velocity/acceleration diagram is inaccurate here; use the exact "
               "values in the reference JSON's 'cases', not this number, for anything tighter "
               'than rel_tol')


def _answer(scene, source, quantity, accessor, printed, unit, rel_tol, kind, **extra):
    entry = {'scene': scene, 'source': source, 'quantity': quantity,
             'accessor': accessor, 'printed': printed, 'unit': unit,
             'rel_tol': rel_tol, 'kind': kind}
    entry.update(extra)
    return entry


TEXTBOOK_ANSWERS = [
    # --- quick_return: Khurmi Example 8.10 (geometry fitted, see the scene) ---
    _answer('quick_return', _KHURMI_8_10, 'omega_BA, |crank angular velocity|',
            ('joint', 'crank', 'velocity', 'abs'), 12.57, 'rad/s', REL_COMPUTED, 'computed'),
    _answer('quick_return', _KHURMI_8_10, 'v_BA = omega_BA * AB, |v_B|',
            ('point', 'B', 'velocity', 'norm'), 1.9, 'm/s', 0.03, 'computed',
            note='printed to 2 significant figures (12.57 * 0.15 = 1.885)'),
    _answer('quick_return', _KHURMI_8_10, 'a^r_BA = omega_BA^2 * AB, |a_B|',
            ('point', 'B', 'acceleration', 'norm'), 23.7, 'm/s^2', REL_COMPUTED, 'computed'),
    _answer('quick_return', _KHURMI_8_10, "v_BB', slip of the block in the slot, |ds/dt|",
            ('joint', 'block', 'velocity', 'abs'), 1.05, 'm/s', REL_MEASURED, 'measured'),
    _answer('quick_return', _KHURMI_8_10, 'v_DC = |omega_CD| * CD',
            ('product', 0.2, (('link_CD', 'velocity', 1),)), 0.45, 'm/s',
            REL_MEASURED, 'measured'),
    _answer('quick_return', _KHURMI_8_10, "v_B'O = |omega_lever| * OB'",
            ('product', 1.0, (('lever', 'velocity', 1), ('block', 'position', 1))), 1.55,
            'm/s', REL_MEASURED, 'measured'),
    _answer('quick_return', _KHURMI_8_10, 'v_CO, |v_C| (C on the lever, OC = 0.7 m)',
            ('point', 'C', 'velocity', 'norm'), 2.15, 'm/s', REL_MEASURED, 'measured'),
    _answer('quick_return', _KHURMI_8_10,
            'omega_lever = v_CO / OC, anticlockwise (signed, + CCW)',
            ('joint', 'lever', 'velocity', 'signed'), 3.07, 'rad/s', REL_MEASURED,
            'derived from measured'),
    _answer('quick_return', _KHURMI_8_10, "B'O, distance of the block from O (slider s)",
            ('joint', 'block', 'position', 'abs'), 0.52, 'm', REL_MEASURED, 'measured'),
    _answer('quick_return', _KHURMI_8_10, "a^c_BB' = 2 * omega_lever * v_BB' (Coriolis)",
            ('product', 2.0, (('lever', 'velocity', 1), ('block', 'velocity', 1))), 6.45,
            'm/s^2', REL_MEASURED_SQUARED, 'derived from measured'),
    _answer('quick_return', _KHURMI_8_10, 'a^r_DC = v_DC^2 / CD = omega_CD^2 * CD',
            ('product', 0.2, (('link_CD', 'velocity', 2),)), 1.01, 'm/s^2',
            REL_MEASURED_SQUARED, 'derived from measured'),
    _answer('quick_return', _KHURMI_8_10, "a^r_B'O = v_B'O^2 / B'O = omega_lever^2 * OB'",
            ('product', 1.0, (('lever', 'velocity', 2), ('block', 'position', 1))), 4.62,
            'm/s^2', REL_MEASURED_SQUARED, 'derived from measured'),
    _answer('quick_return', _KHURMI_8_10, "a^t_B'O = |alpha_lever| * OB'",
            ('product', 1.0, (('lever', 'acceleration', 1), ('block', 'position', 1))), 6.4,
            'm/s^2', REL_MEASURED, 'measured'),
    _answer('quick_return', _KHURMI_8_10, "alpha_lever = a^t_B'O / B'O = 6.4 / 0.52",
            ('joint', 'lever', 'acceleration', 'abs'), 12.3, 'rad/s^2',
            REL_MEASURED_SQUARED, 'derived from measured',
            note='the seed text stops before the division; 6.4/0.52 = 12.31, as Khurmi '
                 'prints'),
    # --- geneva: Beer & Johnston sample problem, computed in the text ---
    _answer('geneva', _GENEVA, 'v_P = R * omega_D, |v_P|',
            ('point', 'P', 'velocity', 'norm'), 0.5, 'm/s', REL_COMPUTED, 'computed',
            note='printed 500 mm/s'),
    _answer('geneva', _GENEVA, 'r = |O_S P|, law of cosines (slider s)',
            ('joint', 'pin_slot', 'position', 'abs'), 0.0371, 'm', REL_COMPUTED, 'computed',
            note='printed 37.1 mm'),
    _answer('geneva', _GENEVA, 'beta, angle of the slot from the line of centres, degrees',
            ('product', 180.0 / math.pi, (('wheel', 'position', 1),)), 42.4, 'deg',
            REL_COMPUTED, 'computed'),
    _answer('geneva', _GENEVA, "v_P' = r * |omega_S|, velocity of the wheel point under P",
            ('product', 1.0, (('wheel', 'velocity', 1), ('pin_slot', 'position', 1))), 0.1512,
            'm/s', REL_COMPUTED, 'computed', note='printed 151.2 mm/s'),
    _answer('geneva', _GENEVA, 'omega_S, wheel angular velocity (signed, clockwise)',
            ('joint', 'wheel', 'velocity', 'signed'), -4.08, 'rad/s', REL_COMPUTED,
            'computed'),
    _answer('geneva', _GENEVA, 'v_P/s, pin velocity along the slot (signed: toward S)',
            ('joint', 'pin_slot', 'velocity', 'signed'), -0.477, 'm/s', REL_COMPUTED,
            'computed', note='printed 477 mm/s along (-cos 42.4 i - sin 42.4 j), inward'),
    _answer('geneva',
            'not in the seed text: Beer & Johnston, the acceleration sample problem that '
            'follows Sample Problem 15.9 (same Geneva mechanism, phi = 150 deg)',
            'alpha_S, wheel angular acceleration (signed, clockwise)',
            ('joint', 'wheel', 'acceleration', 'signed'), -233.0, 'rad/s^2', REL_COMPUTED,
            'computed'),
    # --- rocking_lever: Dunn Example-2 (wheel angle fitted, see the scene) ---
    _answer('rocking_lever', _ROCKING, 'v_B = omega * BC, |v_B|',
            ('point', 'B', 'velocity', 'norm'), 2.5, 'm/s', REL_COMPUTED, 'computed'),
    _answer('rocking_lever', _ROCKING, 'v_A = (v_A)_O, |v_A|',
            ('point', 'A', 'velocity', 'norm'), 1.85, 'm/s', REL_MEASURED, 'measured'),
    _answer('rocking_lever', _ROCKING, 'v_AB = (v_A)_B = |omega_AB| * AB',
            ('product', 0.1, (('AB', 'velocity', 1),)), 3.75, 'm/s', REL_MEASURED,
            'measured'),
    _answer('rocking_lever', _ROCKING, 'omega_AB = v_AB / AB',
            ('joint', 'AB', 'velocity', 'abs'), 37.5, 'rad/s', REL_MEASURED,
            'derived from measured'),
    _answer('rocking_lever', _ROCKING, 'radial acceleration of BC = omega^2 * BC, |a_B|',
            ('point', 'B', 'acceleration', 'norm'), 250.0, 'm/s^2', REL_COMPUTED,
            'computed'),
    _answer('rocking_lever', _ROCKING, 'radial acceleration of AB = omega_AB^2 * AB',
            ('product', 0.1, (('AB', 'velocity', 2),)), 140.6, 'm/s^2',
            REL_MEASURED_SQUARED, 'derived from measured'),
    _answer('rocking_lever', _ROCKING, 'radial acceleration of OA = omega_OA^2 * OA',
            ('product', 0.05, (('OA', 'velocity', 2),)), 68.45, 'm/s^2',
            REL_MEASURED_SQUARED, 'derived from measured'),
    _answer('rocking_lever', _ROCKING, '|a_A|',
            ('point', 'A', 'acceleration', 'norm'), 560.0, 'm/s^2', REL_MEASURED,
            'measured'),
    # --- piston_300: Dunn Example-1 (crank angle fitted, see the scene) ---
    _answer('piston_300', _PISTON, '(v_B)_A = omega * AB, |v_B|',
            ('point', 'B', 'velocity', 'norm'), 15.0, 'm/s', REL_COMPUTED, 'computed'),
    _answer('piston_300', _PISTON, 'centripetal acceleration of B = omega^2 * AB, |a_B|',
            ('point', 'B', 'acceleration', 'norm'), 4500.0, 'm/s^2', REL_COMPUTED,
            'computed'),
    _answer('piston_300', _PISTON, '(v_C)_B = |omega_BC| * BC',
            ('product', 0.17, (('rod', 'velocity', 1),)), 7.8, 'm/s', REL_MEASURED,
            'measured'),
    _answer('piston_300', _PISTON, 'centripetal acceleration of C to B = v_CB^2 / BC',
            ('product', 0.17, (('rod', 'velocity', 2),)), 357.9, 'm/s^2',
            REL_MEASURED_SQUARED, 'derived from measured'),
    _answer('piston_300', _PISTON, 'acceleration of the piston, |d^2s/dt^2|',
            ('joint', 'piston', 'acceleration', 'abs'), 1505.0, 'm/s^2', REL_MEASURED,
            'measured'),
    _answer('piston_300', _PISTON, 'tangential acceleration of C relative to B = '
            '|alpha_BC| * BC', ('product', 0.17, (('rod', 'acceleration', 1),)), 4000.0,
            'm/s^2', REL_MEASURED, 'measured'),
    _answer('piston_300', _PISTON, 'alpha_BC = 4000 / 0.17',
            ('joint', 'rod', 'acceleration', 'abs'), 23529.0, 'rad/s^2', REL_MEASURED,
            'derived from measured'),
    # --- four_bar_coupler_points: Problem 3 (AD and angle fitted, see the scene) ---
    _answer('four_bar_coupler_points', _PROBLEM_3, 'v_BA = r_AB * omega_AB, |v_B|',
            ('point', 'B', 'velocity', 'norm'), 0.525, 'm/s', REL_COMPUTED, 'computed'),
    _answer('four_bar_coupler_points', _PROBLEM_3, '(a_BA)n = r_AB * omega_AB^2',
            ('product', 0.05, (('crank', 'velocity', 2),)), 5.51, 'm/s^2', REL_COMPUTED,
            'computed'),
    _answer('four_bar_coupler_points', _PROBLEM_3, '(a_BA)t = r_AB * alpha_AB',
            ('product', 0.05, (('crank', 'acceleration', 1),)), 1.3, 'm/s^2', REL_COMPUTED,
            'computed'),
    _answer('four_bar_coupler_points', _PROBLEM_3, 'v_CB = |omega_BC| * BC',
            ('product', 0.066, (('coupler', 'velocity', 1),)), 0.336, 'm/s', REL_MEASURED,
            'measured'),
    _answer('four_bar_coupler_points', _PROBLEM_3, 'v_CD = |v_C|',
            ('point', 'C', 'velocity', 'norm'), 0.41, 'm/s', REL_MEASURED, 'measured'),
    _answer('four_bar_coupler_points', _PROBLEM_3, '(a_CB)n = v_CB^2 / r_CB',
            ('product', 0.066, (('coupler', 'velocity', 2),)), 1.71, 'm/s^2',
            REL_MEASURED_SQUARED, 'derived from measured'),
    _answer('four_bar_coupler_points', _PROBLEM_3, '(a_CD)n = v_CD^2 / r_CD',
            ('product', 0.056, (('rocker', 'velocity', 2),)), 3.0, 'm/s^2',
            REL_MEASURED_SQUARED, 'derived from measured', note='printed as "3"'),
    # --- khurmi_four_bar_ad150: from the reference JSON ---
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'omega_AB, |crank angular velocity|',
            ('joint', 'crank', 'velocity', 'abs'), 12.57, 'rad/s', 0.005, 'computed',
            exact=12.566370614359172),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'v_B, |v_B|',
            ('point', 'B', 'velocity', 'norm'), 0.503, 'm/s', 0.005, 'computed',
            exact=0.5026548245743669),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'a_BA^n = omega_AB^2 * AB',
            ('product', 0.04, (('crank', 'velocity', 2),)), 6.32, 'm/s^2', 0.005,
            'computed', exact=6.31654681669719),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'omega_BC, |coupler angular velocity|',
            ('joint', 'coupler', 'velocity', 'abs'), 1.073, 'rad/s', 0.2, 'measured',
            exact=1.3086251349486304, discrepancy=True, unreliable=True, note=_UNRELIABLE),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'v_CB = |omega_BC| * BC',
            ('product', 0.15, (('coupler', 'velocity', 1),)), 0.161, 'm/s', 0.2, 'measured',
            exact=0.19629377024229458, discrepancy=True, unreliable=True, note=_UNRELIABLE),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'omega_CD, |rocker angular velocity|',
            ('joint', 'rocker', 'velocity', 'abs'), 5.163, 'rad/s', 0.1, 'measured',
            exact=4.7845709475187395, discrepancy=True, unreliable=True, note=_UNRELIABLE),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'v_C, |v_C|',
            ('point', 'C', 'velocity', 'norm'), 0.413, 'm/s', 0.1, 'measured',
            exact=0.3827656758014992, discrepancy=True, unreliable=True, note=_UNRELIABLE),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'a_CB^n = omega_BC^2 * BC',
            ('product', 0.15, (('coupler', 'velocity', 2),)), 0.173, 'm/s^2', 0.4,
            'derived from measured', exact=0.2568749615728982, discrepancy=True,
            unreliable=True, note=_UNRELIABLE),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'a_CD^n = omega_CD^2 * CD',
            ('product', 0.08, (('rocker', 'velocity', 2),)), 2.13, 'm/s^2', 0.2,
            'derived from measured', exact=1.8313695321472296, discrepancy=True,
            unreliable=True, note=_UNRELIABLE),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'alpha_BC, |coupler angular acceleration|',
            ('joint', 'coupler', 'acceleration', 'abs'), 32.02, 'rad/s^2', 0.05, 'measured',
            exact=31.385444041238184),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'a_CB^t = |alpha_BC| * BC',
            ('product', 0.15, (('coupler', 'acceleration', 1),)), 4.803, 'm/s^2', 0.05,
            'measured', exact=4.707816606185728),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'alpha_CD, |rocker angular acceleration|',
            ('joint', 'rocker', 'acceleration', 'abs'), 49.77, 'rad/s^2', 0.2, 'measured',
            exact=56.88434903456996, discrepancy=True, unreliable=True, note=_UNRELIABLE),
    _answer('khurmi_four_bar_ad150', _FOUR_BAR, 'a_CD^t = |alpha_CD| * CD',
            ('product', 0.08, (('rocker', 'acceleration', 1),)), 3.982, 'm/s^2', 0.2,
            'measured', exact=4.550747922765597, discrepancy=True, unreliable=True,
            note=_UNRELIABLE),
    # --- slider_crank_150_600 and steam_engine_500_2000: from the reference JSON ---
    _answer('slider_crank_150_600', _SLIDER, 'v_D (midpoint of the rod), |v_D|',
            ('point', 'D', 'velocity', 'norm'), 4.1, 'm/s', 0.05, 'measured',
            exact=3.9953581078742966),
    _answer('slider_crank_150_600', _SLIDER, 'a_D (midpoint of the rod), |a_D|',
            ('point', 'D', 'acceleration', 'norm'), 117.0, 'm/s^2', 0.05, 'measured',
            exact=117.31042577013007),
    _answer('steam_engine_500_2000', _STEAM,
            'omega_OB, |crank angular velocity| (text uses pi = 3.142)',
            ('joint', 'crank', 'velocity', 'abs'), 18.852, 'rad/s', 0.005, 'computed',
            exact=18.84955592153876),
    _answer('steam_engine_500_2000', _STEAM, 'v_B, |v_B|',
            ('point', 'B', 'velocity', 'norm'), 9.426, 'm/s', 0.005, 'computed',
            exact=9.42477796076938),
]
