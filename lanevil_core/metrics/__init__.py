"""Lane-detection metrics: the official TuSimple Accuracy/FP/FN (with two F1 variants), CULane F1 and the ego line
match."""

from .culane import CulaneSummary, MatchCounts, iou_matrix, match_image
from .ego import EgoLineScore, EgoSummary, ego_line_match, summarize_ego
from .evaluate import METRICS, ScoredImage, evaluate, score_tusimple_files
from .formats import LaneFileError, LaneRecord, pair_records, read_tusimple
from .tusimple import F1_VARIANTS, ImageScore, TusimpleSummary, score_image, summarize

__all__ = [
    "F1_VARIANTS",
    "METRICS",
    "CulaneSummary",
    "EgoLineScore",
    "EgoSummary",
    "ImageScore",
    "LaneFileError",
    "LaneRecord",
    "MatchCounts",
    "ScoredImage",
    "TusimpleSummary",
    "ego_line_match",
    "evaluate",
    "iou_matrix",
    "match_image",
    "pair_records",
    "read_tusimple",
    "score_image",
    "score_tusimple_files",
    "summarize",
    "summarize_ego",
]
