// The participant's side of the perception study: consent -> instructions -> practice -> rated items -> thanks.
// Nothing is sent before consent. The participant id is kept in localStorage so a reload resumes where it left off.
"use strict";

const STUDY_ID = decodeURIComponent(location.pathname.split("/").filter(Boolean).pop());
const API = `/api/study/studies/${STUDY_ID}`;
const STORAGE_KEY = `lanevil-study:${STUDY_ID}`;
const POST_RETRIES = 4;
const PREPARING_POLL_MS = 2000;

const state = {study: null, plan: null, index: 0, rated: new Set(), scaleShownAt: 0, accepting: false};

const $ = (id) => document.getElementById(id);

function show(screen) {
  for (const section of document.querySelectorAll("body > section")) {
    section.hidden = section.id !== `screen-${screen}`;
  }
  window.scrollTo(0, 0);
}

function bind(values) {
  for (const node of document.querySelectorAll("[data-bind]")) {
    if (node.dataset.bind in values) node.textContent = values[node.dataset.bind];
  }
}

function fail(message) {
  $("error-text").textContent = message;
  show("error");
}

async function request(method, url, body) {
  const options = {method, headers: {}};
  if (body !== undefined) {
    options.headers["Content-Type"] = "application/json";
    options.body = JSON.stringify(body);
  }
  const response = await fetch(url, options);
  const data = await response.json().catch(() => ({}));
  return {status: response.status, data};
}

// A POST that survives a dropped connection: retried with a growing pause. A repeated rating answers 409, which
// means the first attempt did land.
async function post(url, body) {
  for (let attempt = 0; ; attempt++) {
    try {
      const answer = await request("POST", url, body);
      if (answer.status < 500 || attempt >= POST_RETRIES) return answer;
    } catch (error) {
      if (attempt >= POST_RETRIES) throw error;
    }
    await new Promise((resolve) => setTimeout(resolve, 400 * 2 ** attempt));
  }
}

async function start() {
  const answer = await request("GET", `${API}/public`);
  if (answer.status === 404) return fail("This link does not lead to a study. Please check the address.");
  if (answer.status !== 200) return fail(answer.data.detail || "The study could not be loaded.");
  state.study = answer.data;
  const seconds = state.study.viewing_ms / 1000;
  document.title = state.study.title;
  bind({title: state.study.title, consent_text: state.study.consent_text, instructions: state.study.instructions,
        question: state.study.question, viewing: `${seconds} second${seconds === 1 ? "" : "s"}`});
  $("stage").style.aspectRatio = `${state.study.width} / ${state.study.height}`;
  const saved = localStorage.getItem(STORAGE_KEY);
  if (saved) {
    const plan = await request("GET", `${API}/participants/${saved}`);
    if (plan.status === 200) return resume(plan.data);
    localStorage.removeItem(STORAGE_KEY);
  }
  if (state.study.status === "rendering") return waitUntilReady();
  if (state.study.status !== "ready") {
    $("unavailable-text").textContent = "Its images could not be prepared, so it cannot start. Please tell the " +
      "person who sent you the link.";
    return show("unavailable");
  }
  show("consent");
}

// A study whose images are still rendering: show how far it is and open it once it is ready.
async function waitUntilReady() {
  show("preparing");
  for (;;) {
    const preparing = state.study.preparing;
    if (preparing && preparing.total) {
      $("preparing-fill").style.width = `${(100 * preparing.done) / preparing.total}%`;
      $("preparing-text").textContent = `${preparing.done} of ${preparing.total} images ready.`;
    } else {
      $("preparing-text").textContent = "Waiting for the images…";
    }
    await new Promise((resolve) => setTimeout(resolve, PREPARING_POLL_MS));
    const answer = await request("GET", `${API}/public`).catch(() => null);
    if (answer && answer.status === 200) state.study = answer.data;
    if (state.study.status !== "rendering") return start();
  }
}

function resume(plan) {
  state.plan = plan;
  state.rated = new Set(plan.rated);
  if (plan.completed) return show("done");
  state.index = plan.items.findIndex((item) => !state.rated.has(item.item_id));
  if (state.index < 0) return finish();
  if (state.index === 0) return show("instructions");
  runTrial();
}

async function consent() {
  $("consent-yes").disabled = true;
  const answer = await post(`${API}/participants`, {consent: true});
  if (answer.status !== 201) return fail(answer.data.detail || "Could not start the study.");
  localStorage.setItem(STORAGE_KEY, answer.data.participant_id);
  state.plan = answer.data;
  state.index = 0;
  show("instructions");
}

function progress(item) {
  const items = state.plan.items;
  const training = items.filter((entry) => entry.training).length;
  const total = item.training ? training : items.length - training;
  const number = item.training ? state.index + 1 : state.index - training + 1;
  $("progress-label").textContent = item.training ? "Practice" : "Study";
  $("progress-count").textContent = `${number} of ${total}`;
  $("progress-fill").style.width = `${(100 * (number - 1)) / total}%`;
}

function setButtons(enabled) {
  state.accepting = enabled;
  for (const button of document.querySelectorAll("[data-rating]")) button.disabled = !enabled;
}

async function runTrial() {
  const item = state.plan.items[state.index];
  show("trial");
  progress(item);
  setButtons(false);
  $("rating").style.visibility = "hidden";
  $("rating-note").textContent = "";
  const image = $("stimulus");
  image.hidden = true;
  $("stage-hint").textContent = "Loading…";
  const loader = new Image();
  loader.src = item.image_url;
  try {
    await loader.decode();
  } catch (error) {
    return fail("An image could not be loaded. Please check your connection and try again.");
  }
  image.src = loader.src;
  $("stage-hint").textContent = "";
  image.hidden = false;
  // Count the viewing time from the first frame the image is actually painted in.
  await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
  await new Promise((resolve) => setTimeout(resolve, state.plan.viewing_ms));
  image.hidden = true;
  $("stage-hint").textContent = "Rate the image you just saw";
  $("rating").style.visibility = "visible";
  state.scaleShownAt = performance.now();
  setButtons(true);
}

async function submit(value) {
  if (!state.accepting) return;
  setButtons(false);
  const item = state.plan.items[state.index];
  $("rating-note").textContent = "Saving…";
  let answer;
  try {
    answer = await post(`${API}/participants/${state.plan.participant_id}/ratings`,
                        {item_id: item.item_id, rating: value,
                         response_ms: Math.round(performance.now() - state.scaleShownAt)});
  } catch (error) {
    $("rating-note").textContent = "Could not save; check your connection and choose again.";
    return setButtons(true);
  }
  if (answer.status !== 201 && answer.status !== 409) {
    $("rating-note").textContent = answer.data.detail || "Could not save; please choose again.";
    return setButtons(true);
  }
  state.rated.add(item.item_id);
  state.index += 1;
  const next = state.plan.items[state.index];
  if (!next) return finish();
  if (item.training && !next.training) return show("break");
  runTrial();
}

async function finish() {
  const answer = await post(`${API}/participants/${state.plan.participant_id}/complete`);
  if (answer.status !== 200) return fail(answer.data.detail || "Could not finish the study.");
  $("progress-fill").style.width = "100%";
  show("done");
}

document.addEventListener("DOMContentLoaded", () => {
  $("consent-check").addEventListener("change", (event) => { $("consent-yes").disabled = !event.target.checked; });
  $("consent-yes").addEventListener("click", consent);
  $("consent-no").addEventListener("click", () => show("declined"));
  $("start").addEventListener("click", runTrial);
  $("continue").addEventListener("click", runTrial);
  $("retry").addEventListener("click", () => location.reload());
  for (const button of document.querySelectorAll("[data-rating]")) {
    button.addEventListener("click", () => submit(Number(button.dataset.rating)));
  }
  document.addEventListener("keydown", (event) => {
    if (event.key >= "1" && event.key <= "5" && !event.repeat) submit(Number(event.key));
  });
  start().catch((error) => fail(`The study could not be loaded (${error}).`));
});
