/**
 * A frame's detector score line that always ends on the latest requested detections URL.
 *
 * Like `LatestImage`: requests are debounced, a new one aborts the one in flight, and only the latest answer is
 * shown. The line reads "ufld · accuracy 93.8% · FP 0.2 · FN 0"; `data-verdict` is `fooled` when the
 * detector found a false lane or missed one (FP or FN above 0), else `holds`. The URL of the score on display is
 * kept in `dataset.src`.
 */

import { getJson } from "./api.js";
import { DEBOUNCE_MS } from "./latest-image.js";

const NBSP = "\u00a0";  // keeps a name and its number on one line

/** "ufld · accuracy 93.8% · FP 0.2 · FN 0" from a detections answer (rates to two decimals, no trailing 0s). */
export function scoreText(body) {
  const rate = (value) => String(+value.toFixed(2));
  const parts = [["accuracy", `${(100 * body.accuracy).toFixed(1)}%`], ["FP", rate(body.fp)], ["FN", rate(body.fn)]];
  return [body.detector, ...parts.map(([name, value]) => `${name}${NBSP}${value}`)].join(" · ");
}

export class LatestScore {
  /** @param {HTMLElement} line where the score is written (hidden while no detector is chosen) */
  constructor(line) {
    this.line = line;
    this.wanted = null;
    this.timer = 0;
    this.controller = null;
    this.shown = null;  // {url, text, verdict, title} on display
  }

  /** Show the score at `url` for `detector` (none: hide the line), after the debounce delay unless `immediate`. */
  request(url, detector, { immediate = false } = {}) {
    if (url === this.wanted) return;
    this.wanted = url;
    window.clearTimeout(this.timer);
    this.controller?.abort();
    this.controller = null;
    if (!url) {
      this.show(null);
      return;
    }
    if (url === this.shown?.url) {  // back to the score on display
      this.show(this.shown);
      return;
    }
    this.show({ url: null, text: `${detector} · scoring…`, verdict: "pending", title: "" }, { keep: true });
    if (immediate) this.load(url, detector);
    else this.timer = window.setTimeout(() => this.load(url, detector), DEBOUNCE_MS);
  }

  async load(url, detector) {
    const controller = new AbortController();
    this.controller = controller;
    try {
      const body = await getJson(url, { signal: controller.signal });
      if (controller !== this.controller) return;
      this.show({
        url,
        text: scoreText(body),
        verdict: body.fp > 0 || body.fn > 0 ? "fooled" : "holds",
        title: `${body.lanes.length} lanes found, ${body.gt_lanes.length} labelled: TuSimple scores of this frame `
          + "against its ground truth (the detector's lanes are drawn in magenta)",
      });
    } catch (error) {
      if (controller !== this.controller || error.name === "AbortError") return;
      this.show({ url: null, text: `${detector}: ${error.message}`, verdict: "error", title: "" });
    } finally {
      if (controller === this.controller) this.controller = null;
    }
  }

  /** Write `score` (null: hide the line); `keep`: a placeholder that leaves `shown` alone. */
  show(score, { keep = false } = {}) {
    if (!keep) this.shown = score?.url ? score : null;
    this.line.hidden = !score;
    this.line.textContent = score?.text ?? "";
    this.line.title = score?.title ?? "";
    if (score) this.line.dataset.verdict = score.verdict;
    else delete this.line.dataset.verdict;
    if (score?.url) this.line.dataset.src = score.url;
    else delete this.line.dataset.src;
  }
}
