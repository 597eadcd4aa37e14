# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The step kinds a scene's dyads may name: ``type:`` -> the kind's item class.

Adding a kind is one module (its item and step, :mod:`.base`) and one entry here.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .actuator import Actuator
from .base import Driver, Item
from .collar import Collar
from .crank import Crank
from .fold import Fold
from .hinge import Hinge, Motor
from .model import SceneUnits
from .rpp import RPP
from .rpr import RPR
from .rrp import RRP
from .rrr import RRR
from .slider import Slider
from .triad import Triad

_ITEMS: tuple[type[Item], ...] = (RRR, RRP, RPR, RPP, Triad, Collar, Hinge, Fold)
#: The scene's ``type:`` of a dyad -> its item class.
KINDS: dict[str, type[Item]] = {kind.kind: kind for kind in _ITEMS}

#: The key that names a driver in the scene's ``inputs:`` -> its kind.
_DRIVERS: tuple[type[Driver], ...] = (Crank, Actuator, Slider, Motor)
DRIVERS: dict[str, type[Driver]] = {kind.scene_key: kind for kind in _DRIVERS}

#: The ``kind`` of an :class:`~mech_kinematics.errors.AssemblyError`'s facts -> their text.
FACT_TEXTS: dict[str, Callable[[dict[str, Any], SceneUnits], str]] = {
    fact: text for kind in (*KINDS.values(), *DRIVERS.values())
    for fact, text in kind.fact_texts().items()}
