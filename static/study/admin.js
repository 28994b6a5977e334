// The organiser's page: list studies, show MOS with 95 % confidence intervals, download the CSV exports.
"use strict";

const TOKEN_KEY = "lanevil-study-admin-token";
const GROUP_TITLES = {overall: "All scored items", source: "By source (synthetic vs real)",
                      illusion_type: "By illusion type (synthetic)", severity: "By severity (synthetic)",
                      item: "By item"};
const $ = (id) => document.getElementById(id);

function headers() {
  return {Authorization: `Bearer ${sessionStorage.getItem(TOKEN_KEY) || ""}`};
}

async function getJson(url) {
  const response = await fetch(url, {headers: headers()});
  const data = await response.json().catch(() => ({}));
  if (!response.ok) throw new Error(data.detail || `HTTP ${response.status}`);
  return data;
}

function cell(row, text, numeric = false) {
  const td = row.insertCell();
  td.textContent = text;
  if (numeric) td.className = "num";
  return td;
}

const fixed = (value) => (value === null || value === undefined ? "–" : value.toFixed(2));

async function listStudies() {
  $("admin-error").textContent = "";
  try {
    const studies = await getJson("/api/study/studies");
    const body = $("studies").tBodies[0];
    body.replaceChildren();
    for (const study of studies) {
      const detail = await getJson(`/api/study/studies/${study.id}`);
      const row = body.insertRow();
      cell(row, study.title);
      cell(row, study.id);
      cell(row, statusText(study, detail));
      cell(row, String(detail.items.length), true);
      cell(row, String(study.participants), true);
      const link = document.createElement("a");
      link.href = `/study/${study.id}`;
      link.textContent = `/study/${study.id}`;
      cell(row, "").append(link);
      const button = document.createElement("button");
      button.textContent = "Results";
      button.addEventListener("click", () => showResults(study.id));
      cell(row, "").append(button);
    }
    $("studies").hidden = studies.length === 0;
    $("no-studies").hidden = studies.length > 0;
    $("create").hidden = false;
    document.dispatchEvent(new CustomEvent("organiser-ready"));
    if (location.hash.length > 1) showResults(location.hash.slice(1));
  } catch (error) {
    $("admin-error").textContent = error.message;
  }
}

function statusText(study, detail) {
  if (study.status === "rendering" && detail.job) return `rendering ${detail.job.done}/${detail.job.total}`;
  if (study.status === "failed") return `failed: ${study.error || "see the server log"}`;
  return study.status;
}

function itemLabel(item) {
  const what = item.case_id ? `${item.case_id} @ frame ${item.frame}` : item.upload_name;
  return `#${item.position} ${item.source}: ${what}`;
}

function groupTable(name, groups, labels) {
  const table = document.createElement("table");
  table.className = "groups";
  const head = table.createTHead().insertRow();
  for (const [title, numeric] of [["Group", false], ["n", true], ["MOS", true], ["95% CI", true], ["SD", true]]) {
    const th = document.createElement("th");
    th.textContent = title;
    if (numeric) th.className = "num";
    head.append(th);
  }
  const body = table.createTBody();
  for (const [group, result] of Object.entries(groups)) {
    const row = body.insertRow();
    cell(row, labels[group] || group);
    cell(row, String(result.n), true);
    cell(row, fixed(result.mos), true);
    cell(row, result.ci_low === null ? "–" : `${fixed(result.ci_low)} – ${fixed(result.ci_high)}`, true);
    cell(row, fixed(result.std), true);
  }
  const heading = document.createElement("h2");
  heading.textContent = GROUP_TITLES[name] || name;
  return [heading, table];
}

async function showResults(studyId) {
  try {
    const results = await getJson(`/api/study/studies/${studyId}/results`);
    const detail = await getJson(`/api/study/studies/${studyId}`);
    const labels = Object.fromEntries(detail.items.map((item) => [String(item.id), itemLabel(item)]));
    location.hash = studyId;
    const people = results.participants;
    const reasons = people.excluded_by_reason;
    $("results-title").textContent = `Results: ${results.study.title}`;
    $("results-people").textContent =
      `${people.total} participant${people.total === 1 ? "" : "s"}, ${people.included} included, ` +
      `${people.excluded} excluded ` +
      `(failed gold: ${reasons.gold}, failed trap: ${reasons.trap}, incomplete: ${reasons.incomplete}). ` +
      `${results.ratings.used} of ${results.ratings.total} ratings enter the MOS.`;
    const tables = $("results-tables");
    tables.replaceChildren();
    for (const [name, groups] of Object.entries(results.groups)) {
      tables.append(...groupTable(name, groups, name === "item" ? labels : {}));
    }
    $("download-ratings").onclick = () => download(`/api/study/studies/${studyId}/ratings.csv`);
    $("download-summary").onclick = () => download(`/api/study/studies/${studyId}/summary.csv`);
    $("results").hidden = false;
  } catch (error) {
    $("admin-error").textContent = error.message;
  }
}

async function download(url) {
  const response = await fetch(url, {headers: headers()});
  if (!response.ok) return ($("admin-error").textContent = `download failed (HTTP ${response.status})`);
  const name = /filename="([^"]+)"/.exec(response.headers.get("Content-Disposition") || "")?.[1] || "study.csv";
  const link = document.createElement("a");
  link.href = URL.createObjectURL(await response.blob());
  link.download = name;
  link.click();
  URL.revokeObjectURL(link.href);
}

document.addEventListener("DOMContentLoaded", () => {
  $("token").value = sessionStorage.getItem(TOKEN_KEY) || "";
  $("token-form").addEventListener("submit", (event) => {
    event.preventDefault();
    sessionStorage.setItem(TOKEN_KEY, $("token").value.trim());
    listStudies();
  });
  if ($("token").value) listStudies();
  document.addEventListener("study-created", listStudies);
});
