// The organiser's "New study" form: rendered cases x frames, real photos, practice/gold/trap items -> one
// multipart POST /api/study/studies (a `spec` JSON field plus the photos as `files`), then the study's progress.
"use strict";

const CREATE_TOKEN_KEY = "lanevil-study-admin-token";
const ROLE_NAMES = {training: "Practice", gold: "Gold", trap: "Trap"};
const ACR = {5: "Excellent", 4: "Good", 3: "Fair", 2: "Poor", 1: "Bad"};
const POLL_MS = 1500;
const byId = (id) => document.getElementById(id);
const form = {cases: [], loaded: false};

function authHeaders() {
  return {Authorization: `Bearer ${sessionStorage.getItem(CREATE_TOKEN_KEY) || ""}`};
}

function element(tag, props = {}, children = []) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

// --- cameras: the presets a study may see its cases through, as the API's schema lists them ------------------------

async function loadCameras() {
  const select = byId("spec-camera");
  if (select.options.length > 1) return;
  const response = await fetch("/openapi.json");
  if (!response.ok) return;
  const schema = (await response.json()).components.schemas.StudySpec.properties.camera;
  const presets = (schema.anyOf || [schema]).flatMap((option) => option.enum || []).filter(Boolean);
  select.append(...presets.map((name) => element("option", {
    value: name, textContent: name === "carla" ? "carla (the paper's capture camera)" : name})));
}

// --- cases -----------------------------------------------------------------------------------------------------

async function loadCases() {
  if (form.loaded) return;
  const response = await fetch("/api/cases");
  if (!response.ok) return status(`The case list could not be loaded (HTTP ${response.status}).`, true);
  form.cases = (await response.json()).data;
  form.loaded = true;
  const list = byId("case-list");
  list.replaceChildren(...form.cases.map((entry) => {
    const box = element("input", {type: "checkbox", value: entry.id});
    box.addEventListener("change", summarize);
    const what = entry.type ? `${entry.type.replaceAll("_", " ")}, level ${entry.severity}` : "no illusion";
    return element("label", {className: "check", title: entry.id}, [
      box, element("span", {textContent: entry.title || entry.id}),
      element("small", {textContent: `${entry.id} · ${what} · ${entry.frames} frames`})]);
  }));
  for (const row of byId("qc-items").tBodies[0].rows) fillSources(row);
  summarize();
}

function filterCases() {
  const words = byId("case-filter").value.toLowerCase().split(/\s+/).filter(Boolean);
  for (const label of byId("case-list").children) {
    const text = label.textContent.toLowerCase();
    label.hidden = !words.every((word) => text.includes(word));
  }
}

function chosenCases() {
  return [...byId("case-list").querySelectorAll("input:checked")].map((box) => box.value);
}

// "0, 40, 80" or "0:100:20" (start:stop:step, stop excluded) -> [0, 40, 80]
function parseFrames(text) {
  const frames = [];
  for (const part of text.split(/[,\s]+/).filter(Boolean)) {
    const range = /^(\d+):(\d+)(?::(\d+))?$/.exec(part);
    if (range) {
      const [start, stop, step] = [Number(range[1]), Number(range[2]), Number(range[3] || 1)];
      if (step < 1 || stop <= start) throw new Error(`frames: ${part} is an empty range`);
      for (let frame = start; frame < stop; frame += step) frames.push(frame);
    } else if (/^\d+$/.test(part)) {
      frames.push(Number(part));
    } else {
      throw new Error(`frames: ${part} is not a frame number (write e.g. 0, 40, 80 or 0:100:20)`);
    }
  }
  if (!frames.length) throw new Error("frames: give at least one frame number, e.g. 0");
  return [...new Set(frames)];
}

// --- practice, gold and trap items -------------------------------------------------------------------------------

function uploadNames() {
  return [...byId("spec-files").files].map((file) => file.name);
}

function fillSources(row) {
  const select = row.querySelector("[data-key=source]");
  const before = select.value;
  const rendered = element("optgroup", {label: "Rendered case"},
                           form.cases.map((entry) => element("option", {value: `case:${entry.id}`,
                                                                        textContent: entry.id})));
  const photos = element("optgroup", {label: "Uploaded photo"},
                         uploadNames().map((name) => element("option", {value: `upload:${name}`,
                                                                       textContent: name})));
  select.replaceChildren(rendered, ...(photos.children.length ? [photos] : []));
  if ([...select.options].some((option) => option.value === before)) select.value = before;
  sourceChanged(row);
}

function ratingSelect(key, value) {
  const select = element("select", {}, [5, 4, 3, 2, 1].map((rating) =>
    element("option", {value: String(rating), textContent: `${rating} ${ACR[rating]}`})));
  select.dataset.key = key;
  select.value = String(value);
  return select;
}

function sourceChanged(row) {
  const isCase = row.querySelector("[data-key=source]").value.startsWith("case:");
  row.querySelector("[data-key=frame]").disabled = !isCase;
}

function addItem(role) {
  const source = element("select");
  source.dataset.key = "source";
  source.setAttribute("aria-label", "image");
  source.addEventListener("change", () => { sourceChanged(row); summarize(); });
  const frame = element("input", {type: "number", min: "0", step: "1", value: "0", className: "narrow"});
  frame.dataset.key = "frame";
  frame.setAttribute("aria-label", "frame");
  const garble = element("input", {type: "checkbox", checked: role === "gold"});
  garble.dataset.key = "garble";
  garble.setAttribute("aria-label", "scrambled");
  let check;
  if (role === "gold") {
    check = element("span", {className: "range"}, [ratingSelect("low", 1), " to ", ratingSelect("high", 2)]);
  } else if (role === "trap") {
    check = element("span", {}, ["the banner asks for ", ratingSelect("answer", 2)]);
  } else {
    check = element("span", {className: "muted", textContent: "not scored"});
  }
  const remove = element("button", {type: "button", className: "quiet", textContent: "Remove"});
  const row = element("tr", {}, [
    element("td", {textContent: ROLE_NAMES[role]}), element("td", {}, [source]), element("td", {className: "num"},
                                                                                       [frame]),
    element("td", {}, [garble]), element("td", {}, [check]), element("td", {}, [remove])]);
  row.dataset.role = role;
  remove.addEventListener("click", () => { row.remove(); summarize(); });
  byId("qc-items").tBodies[0].append(row);
  fillSources(row);
  summarize();
}

function itemSpec(row) {
  const value = (key) => row.querySelector(`[data-key=${key}]`);
  const [kind, ...rest] = value("source").value.split(":");
  const name = rest.join(":");
  const item = {role: row.dataset.role, garble: value("garble").checked};
  if (kind === "case") Object.assign(item, {case_id: name, frame: Number(value("frame").value || 0)});
  else item.upload = name;
  if (item.role === "gold") item.expect = [Number(value("low").value), Number(value("high").value)];
  if (item.role === "trap") item.answer = Number(value("answer").value);
  return item;
}

// --- the spec and the request ------------------------------------------------------------------------------------

function buildSpec() {
  const text = (id) => byId(id).value.trim();
  const spec = {title: text("spec-title"), viewing_seconds: Number(byId("spec-viewing").value),
                width: Number(byId("spec-width").value), height: Number(byId("spec-height").value),
                items: [...byId("qc-items").tBodies[0].rows].map(itemSpec)};
  if (!spec.title) throw new Error("title: give the study a title");
  for (const [key, id] of [["question", "spec-question"], ["consent_text", "spec-consent"],
                           ["instructions", "spec-instructions"]]) {
    if (text(id)) spec[key] = text(id);
  }
  const cases = chosenCases();
  if (cases.length) spec.generated = {cases, frames: parseFrames(byId("spec-frames").value)};
  if (byId("spec-camera").value) spec.camera = byId("spec-camera").value;
  return spec;
}

function summarize() {
  const rows = byId("qc-items").tBodies[0].rows;
  byId("qc-items").hidden = rows.length === 0;
  let rendered = 0;
  try {
    rendered = chosenCases().length * parseFrames(byId("spec-frames").value).length;
  } catch (error) {
    rendered = 0;
  }
  const shown = new Set([...rows].map((row) => row.querySelector("[data-key=source]").value));
  const photos = uploadNames().filter((name) => !shown.has(`upload:${name}`)).length;
  const counts = Object.keys(ROLE_NAMES).map((role) => [...rows].filter((row) => row.dataset.role === role).length);
  byId("create-summary").textContent =
    `${plural(rendered + photos, "scored image")} (${rendered} rendered, ${plural(photos, "photo")}), ` +
    `${counts[0]} practice, ${counts[1]} gold and ${counts[2]} trap items.`;
}

function plural(count, word) {
  return `${count} ${word}${count === 1 ? "" : "s"}`;
}

function status(message, isError = false) {
  const line = byId("create-status");
  line.textContent = "";
  line.className = isError ? "error" : "";
  if (typeof message === "string") line.textContent = message;
  else line.append(...message);
}

function markItem(field) {
  for (const row of byId("qc-items").tBodies[0].rows) row.classList.remove("invalid");
  const match = /^spec\.items\.(\d+)/.exec(field || "");
  const row = match && byId("qc-items").tBodies[0].rows[Number(match[1])];
  if (row) row.classList.add("invalid");
}

async function submit(event) {
  event.preventDefault();
  markItem(null);
  let spec;
  try {
    spec = buildSpec();
  } catch (error) {
    return status(error.message, true);
  }
  const body = new FormData();
  body.append("spec", JSON.stringify(spec));
  for (const file of byId("spec-files").files) body.append("files", file, file.name);
  byId("create-submit").disabled = true;
  status("Creating the study: rendering its first images…");
  try {
    const response = await fetch("/api/study/studies", {method: "POST", headers: authHeaders(), body});
    const data = await response.json().catch(() => ({}));
    if (!response.ok) {
      markItem(data.field);
      return status(data.detail || `The study was not created (HTTP ${response.status}).`, true);
    }
    document.dispatchEvent(new CustomEvent("study-created"));
    if (response.status === 202) await followRendering(data);
    else created(data);
  } catch (error) {
    status(`The study was not created: ${error.message}`, true);
  } finally {
    byId("create-submit").disabled = false;
  }
}

async function followRendering(study) {
  byId("create-progress").hidden = false;
  let detail = study;
  while (detail.status === "rendering") {
    const job = detail.job || {done: 0, total: 0};
    byId("create-fill").style.width = job.total ? `${(100 * job.done) / job.total}%` : "0";
    status(`Study ${detail.id} is rendering: ${job.done} of ${job.total} images. Participants who open its link ` +
           "now are told to wait.");
    await new Promise((resolve) => setTimeout(resolve, POLL_MS));
    const response = await fetch(`/api/study/studies/${study.id}`, {headers: authHeaders()});
    if (response.ok) detail = await response.json();
  }
  byId("create-progress").hidden = true;
  document.dispatchEvent(new CustomEvent("study-created"));
  if (detail.status === "ready") created(detail);
  else status(`Study ${detail.id} failed while rendering: ${detail.error || "see the server log"}`, true);
}

function created(study) {
  const link = element("a", {href: study.participant_url, textContent: location.origin + study.participant_url});
  status([`Study “${study.title}” is ready with ${study.items.length} images. Send participants to `, link, "."]);
}

document.addEventListener("DOMContentLoaded", () => {
  byId("create-form").addEventListener("submit", submit);
  byId("case-filter").addEventListener("input", filterCases);
  byId("spec-frames").addEventListener("input", summarize);
  byId("spec-files").addEventListener("change", () => {
    for (const row of byId("qc-items").tBodies[0].rows) fillSources(row);
    summarize();
  });
  for (const button of document.querySelectorAll("[data-add]")) {
    button.addEventListener("click", () => addItem(button.dataset.add));
  }
  document.addEventListener("organiser-ready", loadCases);
  document.addEventListener("organiser-ready", loadCameras);
});
