"""95 % intervals for the robustness report: a bootstrap over cases.

The frames of one drive are not independent (neighbouring frames look alike), so the unit of resampling is the
*basic case*: an original with its perturbed levels, every frame of them, named by the parent folder of the
records' ``case`` field (``Shadow/Fence/00_uphill_rural_noon`` for ``Shadow/Fence/00_uphill_rural_noon/03_level3``).
A resample draws as many basic cases as a group of images holds, with replacement, from
``numpy.random.default_rng(seed)``; a figure's interval is the 2.5th to 97.5th percentile of its ``RESAMPLES``
resampled values (the percentile bootstrap). A difference between two detectors or defences is resampled *paired*:
the same cases are drawn for both, so what the cases share cancels out.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import PurePosixPath

import numpy as np

from ..metrics.evaluate import ScoredImage
from ..metrics.tusimple import F1_VARIANTS
from ..typed import FloatArray

RESAMPLES = 2000
SEED = 0
CONFIDENCE = 0.95


def case_unit(image: ScoredImage) -> str:
    """The basic case an image belongs to: the parent of its ``case`` folder, else of its frame's folder."""
    case = image.extra.get("case")
    folder = PurePosixPath(str(case)) if case else PurePosixPath(image.raw_file).parent
    return str(folder.parent)


@dataclass(frozen=True)
class CaseSums:
    """Totals per basic case of one group of images: ``keys`` (G,) and (G,) float64 arrays of the image count
    and the sums of accuracy, FP and FN."""

    keys: tuple[str, ...]
    n: FloatArray
    accuracy: FloatArray
    fp: FloatArray
    fn: FloatArray

    @classmethod
    def of(cls, images: Iterable[ScoredImage]) -> CaseSums:
        """The per-case totals of ``images`` (cases sorted by name)."""
        totals: dict[str, list[float]] = {}
        for image in images:
            row = totals.setdefault(case_unit(image), [0.0, 0.0, 0.0, 0.0])
            row[0] += 1.0
            row[1] += image.score.accuracy
            row[2] += image.score.fp
            row[3] += image.score.fn
        keys = tuple(sorted(totals))
        table = np.array([totals[key] for key in keys], np.float64).reshape(len(keys), 4)
        return cls(keys, table[:, 0], table[:, 1], table[:, 2], table[:, 3])

    def on(self, keys: Sequence[str]) -> CaseSums:
        """The same totals laid out over ``keys`` (zeros for a case this group lacks)."""
        where = {key: i for i, key in enumerate(self.keys)}
        index = np.array([where.get(key, -1) for key in keys], np.int64)
        present = index >= 0

        def pick(values: FloatArray) -> FloatArray:
            out = np.zeros(len(keys), np.float64)
            out[present] = values[index[present]]
            return out

        return CaseSums(tuple(keys), pick(self.n), pick(self.accuracy), pick(self.fp), pick(self.fn))


def resample_weights(count: int, resamples: int = RESAMPLES, seed: int = SEED) -> FloatArray:
    """(resamples, count) float64: how often each of ``count`` cases is drawn in each resample."""
    rng = np.random.default_rng(seed)
    draws = rng.integers(0, max(count, 1), size=(resamples, count))
    weights = np.zeros((resamples, count), np.float64)
    np.add.at(weights, (np.arange(resamples)[:, None], draws), 1.0)
    return weights


def resampled(sums: CaseSums, weights: FloatArray, field: str, f1_variant: str) -> FloatArray:
    """(resamples,) ``field`` ('accuracy' or 'f1') of the images of each resample (NaN where it drew none);
    ``weights`` laid out over ``sums.keys``."""
    n = weights @ sums.n
    with np.errstate(invalid="ignore", divide="ignore"):
        if field == "accuracy":
            return (weights @ sums.accuracy) / n
        fp, fn = (weights @ sums.fp) / n, (weights @ sums.fn) / n
    f1 = np.vectorize(F1_VARIANTS[f1_variant], otypes=[np.float64])
    return np.where(n > 0, f1(np.nan_to_num(fp), np.nan_to_num(fn)), np.nan)


@dataclass(frozen=True)
class Interval:
    """A 95 % interval (fractions, like the figures it bounds)."""

    lo: float
    hi: float

    def contains(self, value: float) -> bool:
        """Whether ``value`` lies within the interval (ends included)."""
        return self.lo <= value <= self.hi

    @property
    def excludes_zero(self) -> bool:
        """Whether 0 lies outside: a difference this interval bounds separates the two things compared."""
        return not self.contains(0.0)


def percentile_interval(samples: FloatArray, confidence: float = CONFIDENCE) -> Interval | None:
    """The central ``confidence`` interval of the finite samples; None when fewer than half are finite."""
    finite = samples[np.isfinite(samples)]
    if finite.size == 0 or finite.size < samples.size / 2:
        return None
    tail = 50.0 * (1.0 - confidence)
    lo, hi = np.percentile(finite, [tail, 100.0 - tail])
    return Interval(float(lo), float(hi))


Term = tuple[float, "CaseSums"]  # (coefficient, images): one term of a linear combination of group means


def combination_interval(terms: Sequence[Term], field: str, f1_variant: str, resamples: int = RESAMPLES,
                         seed: int = SEED) -> Interval | None:
    """Interval of sum(coefficient * ``field`` of the images) over ``terms``, the cases of every term resampled
    together (paired): [(-1, original), (+1, perturbed)] is a gap, [(+1, a), (-1, b)] a paired difference."""
    keys = sorted({key for _, sums in terms for key in sums.keys})
    weights = resample_weights(len(keys), resamples, seed)
    total = np.zeros(resamples, np.float64)
    for coefficient, sums in terms:
        total += coefficient * resampled(sums.on(keys), weights, field, f1_variant)
    return percentile_interval(total)


def gap_interval(original: CaseSums, perturbed: CaseSums, field: str, f1_variant: str) -> Interval | None:
    """Interval of Perturbed - Original of ``field``, the cases of both resampled together."""
    return combination_interval([(-1.0, original), (1.0, perturbed)], field, f1_variant)
