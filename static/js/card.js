/**
 * One illusion card: the stock original next to a perturbed frame, with severity and sun sliders.
 *
 * A card does nothing until `activate()` (called when it scrolls near the viewport). It then looks up the type's
 * cases in the store: the type's representative stock original (`<type>-00_<original>-00_original`, the first of
 * its originals) for the left frame and a level case of the same original (`…-03_level3` preferred) re-rendered
 * at the slider's severity for the right one. Types the store lacks get a "not in this library" card.
 * With a detector chosen (page toolbar), both frames show its lanes in magenta and their captions its TuSimple
 * accuracy on that frame; "Open the editor" opens the card's perturbed case (else its original) in the editor.
 */

import { caseDocument, casesOfType, detectionsUrl, editorUrl, frameUrl } from "./api.js";
import { LatestImage } from "./latest-image.js";
import { LatestScore } from "./latest-score.js";

const PREFERRED_LEVEL = 3;
const LEVELS = 5;

/** "fence_shadow" -> "Fence shadow". */
export function typeTitle(type) {
  const words = type.replaceAll("_", " ");
  return words.charAt(0).toUpperCase() + words.slice(1);
}

const ORIGINAL_STEM = "00_original";

/** The stock id of the case at `level` (0 = the original) in the folder whose original has id `originalId`. */
export function stockId(originalId, level = 0) {
  const folder = originalId.slice(0, -ORIGINAL_STEM.length);
  return level === 0 ? originalId : `${folder}0${level}_level${level}`;
}

/** The id of `type`'s representative original among `ids`: its first stock original
 * (`<type>-00_<original>-00_original`, or `<type>-00_original` of a library with one original per type). */
export function representativeId(type, ids) {
  return [...ids].sort().find((id) => id.startsWith(`${type}-00_`) && id.endsWith(`-${ORIGINAL_STEM}`)) ?? null;
}

/** Ids of the original (or null) and of the case to re-render at any severity (or null) among `rows`. */
export function pickCases(type, rows) {
  const ids = new Set(rows.map((row) => row.id));
  const original = representativeId(type, ids);
  const levels = original === null ? []
    : [PREFERRED_LEVEL, 1, 2, 4, 5].map((level) => stockId(original, level)).filter((id) => ids.has(id));
  const anyPerturbed = rows.find((row) => row.id !== original && row.type === type && row.illusions > 0);
  return { original, perturbed: levels[0] ?? anyPerturbed?.id ?? null };
}

/** Degrees in [0, 360). */
function wrapDegrees(degrees) {
  return ((degrees % 360) + 360) % 360;
}

/** "sun_altitude" -> "sun altitude"; numbers rounded for reading. */
function levelSummary(row) {
  return Object.entries(row)
    .map(([key, value]) => `${key.replaceAll("_", " ")} ${typeof value === "number" ? +value.toFixed(3) : value}`)
    .join(" · ");
}

/** Compass-style words for an azimuth (0 = straight ahead at the start, 90 = left). */
function azimuthWords(degrees) {
  const names = ["ahead", "ahead-left", "left", "behind-left", "behind", "behind-right", "right", "ahead-right"];
  return names[Math.round(wrapDegrees(degrees) / 45) % 8];
}

/** The two frames of a card: [data-role, caption]. */
const FRAME_ROLES = [["original", "Original"], ["perturbed", "Perturbed"]];

export class IllusionCard {
  /**
   * @param {HTMLTemplateElement} template the card markup
   * @param {{name: string, description: string, severity: object[]}} info the type's registry entry
   * @param {{overlay: boolean, detector: string}} display page-wide display options ("" = no detector)
   */
  constructor(template, info, display) {
    this.info = info;
    this.type = info.name;
    this.title = typeTitle(info.name);
    this.display = display;
    this.ids = { original: null, perturbed: null };
    this.sunDefault = null;  // {azimuth, altitude} of the case, once read
    // info.sun: "overrides" (the illusion places the sun; a sun slider overrides it), "table" (its severity table
    // places the sun: no slider moves it, so the sliders are off) or "case" (the case's sun)
    this.sunAuto = info.sun === "overrides" || info.sun === "table";
    this.sunFixed = info.sun === "table";
    this.sunTouched = new Set();  // the sun sliders the user moved: only those go into frame URLs
    this.activated = false;
    this.el = template.content.firstElementChild.cloneNode(true);
    this.build();
  }

  /** Fill the cloned template: ids, labels, texts, listeners. */
  build() {
    const el = this.el;
    el.id = `card-${this.type}`;
    el.dataset.type = this.type;
    el.setAttribute("aria-labelledby", `${this.type}-title`);
    const title = el.querySelector(".card__title");
    title.id = `${this.type}-title`;
    title.textContent = this.title;
    el.querySelector(".card__desc").textContent = this.info.description;
    this.inputs = {};
    this.outputs = {};
    for (const input of el.querySelectorAll("input[data-control]")) {
      const name = input.dataset.control;
      input.id = `${this.type}-${name}`;
      el.querySelector(`label[data-for="${name}"]`).htmlFor = input.id;
      const output = el.querySelector(`output[data-output="${name}"]`);
      output.htmlFor = input.id;
      this.inputs[name] = input;
      this.outputs[name] = output;
      input.addEventListener("input", () => this.onInput(name));
    }
    const frameTemplate = document.getElementById("frame-template");
    const pair = el.querySelector(".pair");
    for (const [role, caption] of FRAME_ROLES) {
      const figure = frameTemplate.content.firstElementChild.cloneNode(true);
      figure.dataset.role = role;
      figure.querySelector(".frame__label").textContent = caption;
      pair.append(figure);
    }
    this.frames = {};
    for (const figure of el.querySelectorAll("figure[data-role]")) {
      const role = figure.dataset.role;
      const img = figure.querySelector("img");
      const loader = new LatestImage(img, {
        onBusy: (busy) => this.setBusy(figure, busy),
        onError: (error) => this.setFrameError(figure, error),
      });
      figure.querySelector(".frame__retry").addEventListener("click", () => loader.retry());
      const score = new LatestScore(figure.querySelector(".frame__score"));
      this.frames[role] = { figure, img, loader, score };
    }
    el.querySelector(".card__reset").addEventListener("click", () => this.reset());
    this.showValues();
  }

  /** Look up the type's cases and show the first frames (once). */
  async activate() {
    if (this.activated) return;
    this.activated = true;
    this.setState("loading");
    let rows;
    try {
      rows = await casesOfType(this.type);
    } catch (error) {
      this.setState("error");
      this.activated = false;
      this.showCardError(`Could not list the ${this.title.toLowerCase()} cases: ${error.message}`,
        () => this.activate());
      return;
    }
    this.showCardError("");
    this.ids = pickCases(this.type, rows);
    for (const [role, id] of Object.entries(this.ids)) {
      this.frames[role].figure.querySelector(".frame__missing").hidden = id !== null;
    }
    this.linkEditor(this.ids.perturbed ?? this.ids.original);
    if (!this.ids.original && !this.ids.perturbed) {
      this.setState("missing");
      const note = this.el.querySelector(".card__missing");
      const heading = Object.assign(document.createElement("strong"), { textContent: "Not in this library" });
      note.replaceChildren(heading, `This server stores no ${this.type} cases. Seed it with the stock library `
        + "(lanevil library) or build one in the editor.");
      note.hidden = false;
      return;
    }
    this.setState("ready");
    this.inputs.severity.disabled = !this.ids.perturbed;
    this.el.querySelector(".card__reset").disabled = false;
    this.refresh({ immediate: true });
    this.readSun(this.ids.perturbed ?? this.ids.original);
  }

  /** Read the case's sun to start the sun sliders from; night scenes keep them off. */
  async readSun(id) {
    try {
      const document = await caseDocument(id);
      const sun = document.sun;
      this.sunDefault = { azimuth: wrapDegrees(sun.azimuth), altitude: sun.altitude };
      const night = sun.intensity <= 0 || sun.altitude <= 0;
      this.inputs.azimuth.disabled = night || this.sunFixed;
      this.inputs.altitude.disabled = night || this.sunFixed;
      const note = this.el.querySelector(".card__note");
      note.hidden = !night && !this.sunAuto;
      note.textContent = night ? "Night scene: lit by street lamps and headlights, so there is no sun to move."
        : this.sunFixed ? "Sun fixed: this illusion's severity table places the sun where its glare needs it, "
          + "so the sun sliders are off."
        : "Sun “auto”: the illusion places the sun itself; a sun slider you move overrides only that angle.";
      this.resetSun();
    } catch (error) {
      this.showCardError(`Could not read the case's sun (${error.message}); the sun sliders stay off.`);
    }
  }

  /** Point "Open the editor" at case `id` (the editor opens it for every tab). */
  linkEditor(id) {
    const link = this.el.querySelector(".card__edit");
    if (!id) return;
    link.href = editorUrl(id);
    link.title = `Open ${id} in the editor`;
    link.dataset.case = id;
  }

  setState(state) {
    this.el.dataset.state = state;
  }

  setBusy(figure, busy) {
    figure.classList.toggle("is-busy", busy);
    figure.setAttribute("aria-busy", String(busy));
  }

  setFrameError(figure, error) {
    const box = figure.querySelector(".frame__error");
    box.hidden = !error;
    box.querySelector(".frame__error-text").textContent = error ? `Render failed: ${error.message}` : "";
    figure.classList.toggle("has-error", Boolean(error));
  }

  /** Show `message` under the frames (none: hide it), with a Retry button when `retry` is given. */
  showCardError(message, retry = null) {
    const box = this.el.querySelector(".card__error");
    box.querySelector(".card__error-text").textContent = message;
    box.hidden = !message;
    const button = box.querySelector(".card__retry");
    button.hidden = !retry;
    button.onclick = retry;
  }

  onInput(name) {
    if (name !== "severity") this.sunTouched.add(name);
    this.showValues();
    this.refresh();
  }

  /** Page-wide options changed (the lane overlay, the detector). */
  displayChanged() {
    if (this.el.dataset.state === "ready") this.refresh({ immediate: true });
  }

  reset() {
    this.inputs.severity.value = String(PREFERRED_LEVEL);
    this.resetSun();
    this.refresh({ immediate: true });
  }

  resetSun() {
    this.sunTouched.clear();
    if (this.sunDefault) {
      this.inputs.azimuth.value = String(this.sunDefault.azimuth);
      this.inputs.altitude.value = String(this.sunDefault.altitude);
    }
    this.showValues();
  }

  /** The control values that go into frame URLs; of the sun only the angles the user moved (an untouched
   * azimuth stays the illusion's own, so moving the altitude alone keeps a shadow across the lanes). */
  settings() {
    const sun = {};
    if (this.sunTouched.has("azimuth")) sun.sunAzimuth = Number(this.inputs.azimuth.value);
    if (this.sunTouched.has("altitude")) sun.sunAltitude = Number(this.inputs.altitude.value);
    return { severity: Number(this.inputs.severity.value), overlay: this.display.overlay,
      detector: this.display.detector, ...sun };
  }

  /** " · sun azimuth 120°, altitude 20°" for the sun angles the user moved, else "". */
  sunCaption() {
    const moved = ["azimuth", "altitude"].filter((name) => this.sunTouched.has(name));
    if (moved.length === 0) return "";
    return ` · sun ${moved.map((name) => `${name} ${this.inputs[name].value}°`).join(", ")}`;
  }

  showValues() {
    const { severity, azimuth, altitude } = this.inputs;
    this.outputs.severity.textContent = `${severity.value} / ${LEVELS}`;
    severity.setAttribute("aria-valuetext", `level ${severity.value} of ${LEVELS}`);
    const known = this.sunDefault !== null;
    const auto = (name) => this.sunAuto && !this.sunTouched.has(name);
    this.outputs.azimuth.textContent = !known ? "–" : auto("azimuth") ? "auto" : `${azimuth.value}°`;
    this.outputs.azimuth.title = auto("azimuth") ? "" : azimuthWords(Number(azimuth.value));
    azimuth.setAttribute("aria-valuetext", auto("azimuth") ? "set by the illusion" : `${azimuth.value} degrees, `
      + azimuthWords(Number(azimuth.value)));
    this.outputs.altitude.textContent = !known ? "–" : auto("altitude") ? "auto" : `${altitude.value}°`;
    altitude.setAttribute("aria-valuetext", auto("altitude") ? "set by the illusion"
      : `${altitude.value} degrees above the horizon`);
    const row = this.info.severity?.[Number(severity.value) - 1];
    this.el.querySelector(".card__level").textContent = row ? `Level ${severity.value}: ${levelSummary(row)}` : "";
    const sun = this.sunCaption();
    this.frames.original.figure.querySelector(".frame__label").textContent = `Original${sun}`;
    this.frames.perturbed.figure.querySelector(".frame__label").textContent =
      `Perturbed · level ${severity.value}${sun}`;
  }

  /** Ask both frames for the pictures (and the detector's scores) of the current settings. */
  refresh({ immediate = false } = {}) {
    const { severity, overlay, detector, sunAzimuth, sunAltitude } = this.settings();
    const angles = [[sunAzimuth, "azimuth"], [sunAltitude, "altitude"]].filter(([value]) => value !== undefined);
    const sun = angles.length ? `, sun at ${angles.map(([value, name]) => `${value}° ${name}`).join(" and ")}` : "";
    const lanes = (overlay ? ", ground-truth lanes drawn" : "") + (detector ? `, ${detector} lanes in magenta` : "");
    const views = {
      original: [{ sunAzimuth, sunAltitude }, `${this.title}: original frame without the illusion`],
      perturbed: [{ severity, sunAzimuth, sunAltitude }, `${this.title} at severity ${severity} of ${LEVELS}`],
    };
    for (const [role, [overrides, alt]] of Object.entries(views)) {
      const id = this.ids[role];
      if (!id) continue;
      const { loader, score } = this.frames[role];
      loader.request(frameUrl(id, { overlay, detector, ...overrides }), `${alt}${sun}${lanes}`, { immediate });
      score.request(detector ? detectionsUrl(id, { detector, ...overrides }) : null, detector, { immediate });
    }
  }
}
