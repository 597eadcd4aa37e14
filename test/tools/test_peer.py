# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``bench --peer pylinkage``: the side-by-side table, and its check that the answers agree."""

import json

import pytest

from mech_kinematics.scene import load_scene
from mech_kinematics.solver import solve
from mech_kinematics.tools import bench, peer

#: Steps a turn of the equality checks below.
STEPS = 360


def _built(name, change=None):
    """Return the scene and its pylinkage twin, one geometry entry changed as ``change`` says."""
    scene = load_scene(name)
    kind, geometry = bench.geometry_of(scene)
    if change is not None:
        index, value = change
        geometry = (*geometry[:index], value, *geometry[index + 1:])
    start = tuple(solve(scene, scene.input.angle).points[scene.dyads[0].key].position)
    linkage, _ = peer.peer_linkage(kind, geometry, scene.input.angle, scene.input.speed,
                                   STEPS, start)
    return scene, linkage


@pytest.mark.parametrize('name', peer.PEER_SCENES)
def test_same_geometry_gives_the_same_answers(name):
    """Over a turn, pylinkage's p, v, a of the crank tip and the output equal ours to 1e-8."""
    scene, linkage = _built(name)
    assert peer.check_same_answers(scene, linkage, STEPS) <= peer.RTOL_PEER


@pytest.mark.parametrize(('name', 'change'), [
    ('khurmi_four_bar_ad150', (4, 0.081)),     # the rocker 1 mm longer
    ('slider_crank_150_600', (3, 0.601)),      # the rod 1 mm longer
])
def test_a_wrong_geometry_fails_the_check(name, change):
    """A peer built with one link 1 mm off is refused before anything is timed."""
    scene, linkage = _built(name, change)
    with pytest.raises(ValueError, match='not the same geometry'):
        peer.check_same_answers(scene, linkage, STEPS)


def test_peer_mode_prints_every_work_item_of_both_scenes(capsys):
    """`bench --peer pylinkage --json`: both scenes, three work items, spreads ordered."""
    assert bench.main(['--peer', 'pylinkage', '--repeat', '1', '--json']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['peer'] == 'pylinkage' and data['repeat'] == 1
    assert [row['scene'] for row in data['rows']] == list(peer.PEER_SCENES)
    for row in data['rows']:
        assert 0 <= row['max_difference'] <= peer.RTOL_PEER and row['cold_s'] >= 0
        for key, _ in peer.work_items():
            for side in ('ours_us', 'theirs_us'):
                low, mid, high = row[key][side]
                assert 0 < low <= mid <= high


def test_peer_table_gives_their_median_over_ours():
    """The ratio column is their median over ours (above 1 where ours is faster)."""
    spread = {'ours_us': [1.0, 2.0, 3.0], 'theirs_us': [4.0, 5.0, 6.0]}
    row = {'scene': 's', 'cold_s': 1.5, 'max_difference': 1e-15,
           **{key: spread for key, _ in peer.work_items()}}
    lines = peer.peer_table([row], 7)
    assert 'of 7 runs' in lines[0] and '1.50 s' in lines[1]
    assert [line.split()[-3:] for line in lines[3:]] == [['1/2/3', '4/5/6', '2.50']] * 3


def test_peer_mode_refuses_a_scene_without_a_peer_twin():
    """A scene that is not a four-bar or slider-crank is refused with one line."""
    for name in ('geneva', 'scotch_yoke'):
        with pytest.raises(ValueError, match='Expected a four-bar or a slider-crank'):
            bench.measure_peers(1, [name])


def test_peer_mode_without_pylinkage_says_how_to_install_it(monkeypatch, capsys):
    """Where pylinkage is not installed: one line naming the dev dependency, exit 2."""
    def missing():
        msg = 'Expected pylinkage 1.3.0 installed, got No module named pylinkage'
        raise ValueError(msg)

    monkeypatch.setattr(peer, '_pylinkage', missing)
    assert bench.main(['--peer', 'pylinkage']) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'make install' in err
