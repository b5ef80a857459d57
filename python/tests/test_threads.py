"""Renders only read a scene: threads render one scene at once, each with its own seed and samples,
and get the images of the same renders one after another."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np

import volpt
from conftest import CUBE, SETTINGS


def test_threads_render_one_scene_at_once_as_one_after_another():
    scene = volpt.load(CUBE, SETTINGS)
    asks = [dict(spp=3), dict(spp=3, seed=7), dict(samples=range(1, 4), seed=2), dict(spp=2, seed=7)]
    serial = [scene.render(**ask).image() for ask in asks]
    fingerprint, seed = scene.fingerprint, scene.params["seed"]
    with ThreadPoolExecutor(max_workers=2 * len(asks)) as pool:
        films = list(pool.map(lambda ask: scene.render(**ask), asks + asks))
    for k, film in enumerate(films):
        assert np.array_equal(np.asarray(film.image()), np.asarray(serial[k % len(asks)])), asks[k % len(asks)]
    # And leave the scene as it was.
    assert scene.fingerprint == fingerprint and scene.params["seed"] == seed
    assert films[1].seed == 7 and films[0].seed == seed
