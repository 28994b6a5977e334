"""Road-surface texture generators: determinism, ranges, coverage against their parameters, thin antialiased lines."""

from __future__ import annotations

import numpy as np
import pytest

from lanevil_core.world import surface_textures as tex

TEXEL = 0.03
SHAPE = (500, 300)  # 15 m along s by 9 m across t


def rng(seed: int = 7) -> np.random.Generator:
    return np.random.default_rng(seed)


def generate(name: str, seed: int = 7, **kw) -> tex.Texture:
    if name in tex.CRACK_KINDS:
        return tex.crack_network(rng(seed), SHAPE, TEXEL, name, **{"density": 2.0, **kw})
    if name == "patches":
        return tex.patches(rng(seed), SHAPE, TEXEL, **{"strips": 3, "parallel_t": (4.5,), **kw})
    if name == "ghost_lines":
        return tex.ghost_lines(rng(seed), SHAPE, TEXEL, **{"t_local": (3.0, 6.0), **kw})
    if name == "worn_paint":
        return tex.worn_paint(rng(seed), SHAPE, TEXEL, **{"t_local": (4.5,), "wear": 0.5,
                                                            "asphalt_rgb": (0.055, 0.055, 0.058), **kw})
    return tex.tire_marks(rng(seed), SHAPE, TEXEL, **{"straight": 1, "swerve": 1, "yaw": 1, **kw})


GENERATORS = (*tex.CRACK_KINDS, "patches", "tire_marks", "ghost_lines", "worn_paint")


@pytest.mark.parametrize("name", GENERATORS)
def test_deterministic_in_range_and_seed_dependent(name: str) -> None:
    rgba, wet = generate(name)
    again, wet_again = generate(name)
    other, _ = generate(name, seed=8)
    assert rgba.dtype == np.float32 and rgba.shape == (*SHAPE, 4)
    assert np.array_equal(rgba, again)
    assert (wet is None) == (wet_again is None)
    assert np.isfinite(rgba).all() and rgba.min() >= 0.0 and rgba.max() <= 1.0
    assert rgba[..., 3].max() > 0.3, "nothing visible was drawn"
    assert not np.array_equal(rgba, other)


@pytest.mark.parametrize("kind", tex.CRACK_KINDS)
def test_crack_coverage_grows_with_density(kind: str) -> None:
    coverage = [generate(kind, density=d)[0][..., 3].mean() for d in (1.0, 2.0, 4.0, 8.0)]
    assert all(a < b for a, b in zip(coverage, coverage[1:])), coverage


def test_cracks_are_dark_and_darkness_scales_opacity() -> None:
    faint, _ = generate("transverse", darkness=0.3)
    strong, _ = generate("transverse", darkness=0.9)
    covered = strong[..., 3] > 0.5
    assert strong[covered, :3].max() < 0.03  # darker than any asphalt (0.05-0.08)
    assert (strong[..., 3] >= faint[..., 3]).all()
    assert 2.5 < strong[..., 3].mean() / faint[..., 3].mean() <= 3.0  # opacity scales with darkness


def test_crack_hugging_a_line_is_thin_and_antialiased() -> None:
    texel, t_line = 0.01, 1.0
    rgba, _ = tex.crack_network(rng(), (1500, 200), texel, "longitudinal", density=0.0, width_m=0.015,
                                darkness=1.0, along_t=(t_line,))
    alpha = rgba[..., 3]
    cols = (np.arange(200) + 0.5) * texel
    near = np.abs(cols - t_line) < 0.1
    core_rows = (alpha[:, near] > 0.5).any(axis=1)
    assert core_rows.mean() > 0.4, "the crack should follow the line over most of the texture"
    widths = (alpha[core_rows][:, near] > 0.5).sum(axis=1)
    assert np.median(widths) <= 3  # a 1-2 cm core at 1 cm texels
    # Box-filtered edges: between the core and the bare asphalt there are partly covered texels.
    soft = (alpha[:, near] > 0.05) & (alpha[:, near] < 0.5)
    assert soft.sum() > core_rows.sum()
    # Beyond the halo nothing but branches: far columns stay mostly bare.
    assert alpha[:, ~near].mean() < 0.1 * alpha[:, near].mean()


def test_wet_cracks_only_when_asked() -> None:
    _, dry = generate("alligator")
    rgba, wet = generate("alligator", wetness=0.8)
    assert dry is None
    assert wet is not None and wet.shape == SHAPE and 0.0 < wet.max() <= 0.8
    assert (wet[rgba[..., 3] == 0] == 0).all()


def test_unknown_crack_kind_is_rejected() -> None:
    with pytest.raises(ValueError, match="kind"):
        tex.crack_network(rng(), SHAPE, TEXEL, "diagonal")  # type: ignore[arg-type]


def test_patch_and_strip_counts_raise_coverage_and_keep_earlier_items() -> None:
    few, _ = tex.patches(rng(), SHAPE, TEXEL, rectangles=1, blobs=1, strips=1)
    many, _ = tex.patches(rng(), SHAPE, TEXEL, rectangles=3, blobs=3, strips=4)
    assert many[..., 3].mean() > few[..., 3].mean() + 0.01
    assert (many[..., 3] >= few[..., 3] - 1e-6).all()  # adding items never removes the earlier ones


def test_parallel_strip_runs_along_its_line() -> None:
    t_line = 4.5
    rgba, _ = tex.patches(rng(), SHAPE, TEXEL, rectangles=0, blobs=0, parallel_t=(t_line,), strip_width_m=0.1,
                          contrast=1.0)
    alpha = rgba[..., 3]
    cols = (np.arange(SHAPE[1]) + 0.5) * TEXEL
    band = np.abs(cols - t_line) < 0.15
    assert (alpha[:, band].max(axis=1) > 0.5).mean() > 0.4
    assert alpha[:, ~band].max() == 0.0


def test_tire_marks_are_track_pairs_that_fade_at_their_ends() -> None:
    rgba, _ = tex.tire_marks(rng(), SHAPE, TEXEL, straight=1, center_t=(4.5,), length_m=(12.0, 12.0),
                             darkness=0.8, gauge_m=(1.6, 1.6))
    alpha = rgba[..., 3]
    cols = (np.arange(SHAPE[1]) + 0.5) * TEXEL
    profile = alpha.max(axis=0)
    # Two tracks about 1.6 m apart centred on t = 4.5 m, bare between them.
    assert profile[np.abs(cols - 3.7) < 0.1].max() > 0.5 and profile[np.abs(cols - 5.3) < 0.1].max() > 0.5
    assert profile[np.abs(cols - 4.5) < 0.4].max() == 0.0
    along = alpha.max(axis=1)
    marked = np.flatnonzero(along > 0)
    first, last = marked[0], marked[-1]
    assert np.isclose((last - first) * TEXEL, 12.0, atol=0.5)
    assert along[first + 2] < 0.3 * along[(first + last) // 2]  # rubber builds up after the tire locks
    # Antialiased edges: partial coverage beside the full track.
    edge = (alpha > 0.02) & (alpha < 0.6 * along.max())
    assert edge.any()


def test_tire_mark_count_and_darkness_raise_coverage() -> None:
    values = [tex.tire_marks(rng(), SHAPE, TEXEL, straight=n, swerve=n, darkness=d)[0][..., 3].mean()
              for n, d in ((1, 0.4), (2, 0.6), (3, 0.8))]
    assert values[0] < values[1] < values[2]


def test_composite_is_porter_duff_over() -> None:
    bottom = np.zeros((2, 2, 4), np.float32)
    bottom[...] = (0.5, 0.5, 0.5, 1.0)
    top = np.zeros((2, 2, 4), np.float32)
    top[0, 0] = (0.0, 0.0, 0.0, 1.0)
    top[0, 1] = (0.1, 0.1, 0.1, 0.5)
    out = tex.composite(top, bottom)
    assert np.allclose(out[0, 0], (0.0, 0.0, 0.0, 1.0))
    assert np.allclose(out[0, 1], (0.3, 0.3, 0.3, 1.0))
    assert np.allclose(out[1, 1], bottom[1, 1])


def test_crack_mix_of_one_kind_is_that_crack_network() -> None:
    single, _ = tex.crack_network(rng(), SHAPE, TEXEL, "longitudinal", density=2.0, along_t=(2.0,))
    mixed, _ = tex.crack_mix(rng(), SHAPE, TEXEL, {"longitudinal": 2.0}, along_t=(2.0,))
    assert np.array_equal(single, mixed)
    both, _ = tex.crack_mix(rng(), SHAPE, TEXEL, {"longitudinal": 2.0, "alligator": 2.0}, along_t=(2.0,))
    assert (both[..., 3] >= single[..., 3] - 1e-6).all()  # other kinds add cracks, never move these
    with pytest.raises(ValueError, match="kinds"):
        tex.crack_mix(rng(), SHAPE, TEXEL, {"potholes": 1.0})  # type: ignore[dict-item]


def test_crack_layers_put_stains_under_and_open_cracks_over_the_paint() -> None:
    layers = tex.crack_layers(rng(), SHAPE, TEXEL, {"transverse": 2.0}, width_m=0.03, darkness=1.0)
    mixed, _ = tex.crack_mix(rng(), SHAPE, TEXEL, {"transverse": 2.0}, width_m=0.03, darkness=1.0)
    np.testing.assert_allclose(tex.composite(layers.cracks, layers.stains), mixed, atol=1e-5)
    crack, stain = layers.cracks[..., 3] > 0.5, layers.stains[..., 3] > 0.05
    assert crack.any() and layers.cracks[crack, :3].max() < 0.012  # the open crack is near black
    assert (stain & ~crack).sum() > 2 * crack.sum()  # the stained rim reaches beyond the crack
    assert layers.stains[stain, :3].max() < 0.03  # and is darker than any asphalt


def test_spalling_widens_and_darkens_the_stains_only() -> None:
    plain = tex.crack_layers(rng(), SHAPE, TEXEL, {"longitudinal": 2.0}, width_m=0.03, spall=0.0)
    spalled = tex.crack_layers(rng(), SHAPE, TEXEL, {"longitudinal": 2.0}, width_m=0.03, spall=1.0)
    assert np.array_equal(plain.cracks, spalled.cracks)
    assert (spalled.stains[..., 3] > 0.02).sum() > 1.5 * (plain.stains[..., 3] > 0.02).sum()
    assert spalled.stains[..., 3].max() > 1.5 * plain.stains[..., 3].max()


def test_failed_joint_is_a_band_of_alligator_cracking_along_its_line() -> None:
    t_line = 4.5
    layers = tex.crack_layers(rng(), SHAPE, TEXEL, {}, width_m=0.03, darkness=1.0, joint_t=(t_line,))
    alpha = layers.cracks[..., 3]
    cols = (np.arange(SHAPE[1]) + 0.5) * TEXEL
    band = np.abs(cols - t_line) < 1.3  # half widths of 0.55-0.9 m, a wavy rim, a few cm off the line
    assert alpha[:, ~band].max() == 0.0  # nothing but the band
    cracked_rows = np.asarray((alpha[:, np.abs(cols - t_line) < 0.3] > 0.5).any(axis=1))
    assert cracked_rows.mean() > 0.6, "the band runs along most of the line"
    assert cracked_rows[: int(2.0 / TEXEL)].any(), "from the texture's start"
    assert 0.05 < alpha[:, band].mean() < 0.4  # a network of cells, not a solid strip


def test_tire_marks_start_where_asked_even_before_the_texture() -> None:
    alpha = tex.tire_marks(rng(), SHAPE, TEXEL, straight=3, swerve=2, center_t=(3.0, 4.5, 6.0),
                           length_m=(8.0, 10.0), darkness=0.9, start_m=(-4.0, -2.0))[0][..., 3]
    along = alpha.max(axis=1)
    assert along[: int(1.0 / TEXEL)].max() > 0.5  # already dark where the texture begins
    assert along[int(8.5 / TEXEL):].max() == 0.0  # and over before 8 m past its start
    spread = tex.tire_marks(rng(), SHAPE, TEXEL, straight=3, swerve=2, center_t=(3.0, 4.5, 6.0),
                            length_m=(8.0, 10.0), darkness=0.9)[0][..., 3]
    assert spread.max(axis=1)[int(8.5 / TEXEL):].max() > 0.5  # without a range they spread over the texture


def test_patch_across_a_line_covers_it_in_the_first_half() -> None:
    t_line = 4.5
    rgba, _ = tex.patches(rng(), SHAPE, TEXEL, rectangles=0, blobs=0, across_t=(t_line, t_line), contrast=1.0)
    alpha = rgba[..., 3]
    col = int(t_line / TEXEL)
    covered = np.flatnonzero(alpha[:, col] > 0.9)
    assert covered.size * TEXEL > 1.0  # at least a metre of the line lies under fresh asphalt
    assert covered.max() * TEXEL < 0.5 * SHAPE[0] * TEXEL + 2.5  # laid in the first half (plus its half length)


def test_ghost_lines_are_pale_stripes_along_their_lines_only() -> None:
    rgba, _ = tex.ghost_lines(rng(), SHAPE, TEXEL, (4.5,), width_m=0.15, opacity=0.8, dashed_share=0.0)
    alpha = rgba[..., 3]
    cols = (np.arange(SHAPE[1]) + 0.5) * TEXEL
    band = np.abs(cols - 4.5) < 0.15
    assert (alpha[:, band].max(axis=1) > 0.3).mean() > 0.95  # a solid ghost runs the whole length
    assert alpha[:, ~band].max() == 0.0
    assert alpha.max() <= 0.8 + 1e-6
    assert rgba[..., :3][alpha > 0].min() > 0.2  # pale scoured stone, far above asphalt's 0.05


def test_dashed_ghosts_keep_their_gaps() -> None:
    rgba, _ = tex.ghost_lines(rng(), SHAPE, TEXEL, (4.5,), opacity=0.8, dashed_share=1.0)
    painted = rgba[..., 3].max(axis=1) > 0.05
    assert 0.2 < painted.mean() < 0.5  # 3 m painted in every 9 m


def test_paint_wear_grows_with_wear_and_stays_on_the_lines() -> None:
    def cover(wear: float) -> np.ndarray:
        rgba, _ = tex.worn_paint(rng(), SHAPE, TEXEL, (4.5,), wear, (0.055, 0.055, 0.058))
        return rgba[..., 3]

    light, heavy = cover(0.2), cover(0.8)
    assert heavy.mean() > light.mean() > 0.0
    cols = (np.arange(SHAPE[1]) + 0.5) * TEXEL
    assert heavy[:, np.abs(cols - 4.5) > 0.3].max() == 0.0
