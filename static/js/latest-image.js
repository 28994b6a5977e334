/**
 * An <img> that always ends on the latest requested URL.
 *
 * Requests are debounced (slider drags fire many `input` events), a new request aborts the one in flight, and a
 * response is shown only if it is still the latest. Images are fetched rather than assigned to `img.src` so an
 * API error arrives with its message and can be shown next to the picture instead of a broken-image icon.
 * The stable API URL of the picture on display is kept in `img.dataset.src`.
 */

import { checked } from "./api.js";

export const DEBOUNCE_MS = 150;

export class LatestImage {
  /**
   * @param {HTMLImageElement} img the picture to update
   * @param {{onBusy: (busy: boolean) => void, onError: (error: Error | null) => void}} hooks
   */
  constructor(img, { onBusy, onError }) {
    this.img = img;
    this.onBusy = onBusy;
    this.onError = onError;
    this.wanted = null;
    this.timer = 0;
    this.controller = null;
    this.objectUrl = null;
  }

  /** Show `url` (after the debounce delay unless `immediate`); `alt` describes the new picture. */
  request(url, alt, { immediate = false } = {}) {
    if (url === this.wanted) return;
    this.wanted = url;
    this.alt = alt;
    window.clearTimeout(this.timer);
    if (url === this.img.dataset.src) {  // back to the picture on display: drop whatever is pending
      this.controller?.abort();
      this.controller = null;
      this.img.alt = alt;
      this.onBusy(false);
      this.onError(null);
      return;
    }
    this.onBusy(true);
    if (immediate) this.load(url);
    else this.timer = window.setTimeout(() => this.load(url), DEBOUNCE_MS);
  }

  /** Fetch the latest URL again (after an error). */
  retry() {
    const url = this.wanted;
    this.wanted = null;
    if (url) this.request(url, this.alt, { immediate: true });
  }

  async load(url) {
    this.controller?.abort();
    const controller = new AbortController();
    this.controller = controller;
    try {
      const response = await checked(await fetch(url, { signal: controller.signal }));
      const objectUrl = URL.createObjectURL(await response.blob());
      const probe = new Image();
      probe.src = objectUrl;
      await probe.decode();  // swap only decoded pictures: no flash of an empty frame
      if (controller !== this.controller) {
        URL.revokeObjectURL(objectUrl);
        return;
      }
      this.show(url, objectUrl);
      this.onError(null);
    } catch (error) {
      if (controller !== this.controller || error.name === "AbortError") return;
      this.onError(error);
    } finally {
      if (controller === this.controller) {
        this.controller = null;
        this.onBusy(false);
      }
    }
  }

  show(url, objectUrl) {
    const previous = this.objectUrl;
    this.objectUrl = objectUrl;
    this.img.src = objectUrl;
    this.img.alt = this.alt;
    this.img.dataset.src = url;
    this.img.hidden = false;
    if (previous) URL.revokeObjectURL(previous);
  }
}
