/**
 * The demo gallery: one card per registered illusion type, grouped under the page's category sections.
 *
 * Cards are built from `GET /api/illusions` and only start rendering when they come near the viewport, so the
 * first paint needs one small JSON request.
 */

import { detectors, illusions } from "./api.js";
import { IllusionCard } from "./card.js";

const LAZY_MARGIN = "300px 0px";
const DEFAULT_DETECTOR = "ufld";

/**
 * Fill the detector select from `/api/detectors`: built-ins and the server's plug-ins (unavailable ones listed but
 * disabled, detectors trained on real roads marked); returns its value.
 */
async function fillDetectors(select) {
  let list;
  try {
    list = await detectors();
  } catch (error) {
    select.replaceChildren(new Option("none", ""));
    select.title = `Could not list the detectors: ${error.message}`;
    return "";
  }
  const options = [new Option("none", "")];
  for (const entry of list) {
    const accuracy = entry.model?.val_accuracy;
    const kind = entry.real_trained ? `${entry.kind}, real-trained` : entry.kind;
    const option = new Option(`${entry.name} (${entry.available ? kind : "not installed"})`, entry.name);
    option.disabled = !entry.available;
    option.title = !entry.available ? entry.reason ?? ""
      : typeof accuracy === "number" ? `validation accuracy ${(100 * accuracy).toFixed(1)}%` : "";
    options.push(option);
  }
  select.replaceChildren(...options);
  const usable = list.filter((entry) => entry.available).map((entry) => entry.name);
  select.value = usable.includes(DEFAULT_DETECTOR) ? DEFAULT_DETECTOR : usable[0] ?? "";
  return select.value;
}

/** The section of `category`, created at the end of the gallery if the page has none for it. */
function sectionOf(gallery, category) {
  let section = gallery.querySelector(`section[data-category="${category}"]`);
  if (!section) {
    section = document.createElement("section");
    section.className = "category";
    section.id = category;
    section.dataset.category = category;
    const heading = document.createElement("h2");
    heading.textContent = category.replaceAll("_", " ");
    section.append(heading, Object.assign(document.createElement("div"), { className: "cards" }));
    gallery.append(section);
  }
  return section;
}

function showPageError(message) {
  const line = document.getElementById("page-error");
  line.textContent = message;
  line.hidden = false;
}

/** Activate each card once it comes within `LAZY_MARGIN` of the viewport. */
function lazyActivate(cards) {
  if (!("IntersectionObserver" in window)) {
    cards.forEach((card) => card.activate());
    return;
  }
  const byElement = new Map(cards.map((card) => [card.el, card]));
  const observer = new IntersectionObserver((entries) => {
    for (const entry of entries) {
      if (!entry.isIntersecting) continue;
      observer.unobserve(entry.target);
      byElement.get(entry.target).activate();
    }
  }, { rootMargin: LAZY_MARGIN });
  cards.forEach((card) => observer.observe(card.el));
}

async function main() {
  const gallery = document.getElementById("gallery");
  const template = document.getElementById("card-template");
  const overlayToggle = document.getElementById("overlay-toggle");
  const detectorSelect = document.getElementById("detector-select");
  const status = document.getElementById("page-status");
  const display = { overlay: overlayToggle.checked, detector: detectorSelect.value };
  const detectorsRead = fillDetectors(detectorSelect);
  let registry;
  try {
    [registry, display.detector] = await Promise.all([illusions(), detectorsRead]);
  } catch (error) {
    showPageError(`Could not load the illusion registry from /api/illusions: ${error.message}`);
    return;
  }
  const cards = registry.map((info) => new IllusionCard(template, info, display));
  for (const card of cards) sectionOf(gallery, card.info.category).querySelector(".cards").append(card.el);
  for (const section of gallery.querySelectorAll("section[data-category]")) {
    const count = section.querySelectorAll(".card").length;
    section.dataset.count = String(count);
    section.querySelector("h2").dataset.count = `${count} ${count === 1 ? "type" : "types"}`;
  }
  status.textContent = `${cards.length} illusion types`;
  overlayToggle.addEventListener("change", () => {
    display.overlay = overlayToggle.checked;
    cards.forEach((card) => card.displayChanged());
  });
  detectorSelect.addEventListener("change", () => {
    display.detector = detectorSelect.value;
    cards.forEach((card) => card.displayChanged());
  });
  document.body.dataset.ready = "true";
  lazyActivate(cards);
}

main();
