// The study's landing page: list the studies a participant may join (GET /api/study/open).
"use strict";

function plural(count, word) {
  return `${count} ${word}${count === 1 ? "" : "s"}`;
}

function studyEntry(study) {
  const item = document.createElement("li");
  const link = document.createElement("a");
  link.href = study.participant_url;
  link.className = "study-link";
  link.textContent = study.title;
  const facts = document.createElement("span");
  facts.className = "muted";
  const seconds = study.viewing_ms / 1000;
  facts.textContent = `${plural(study.rated_items, "image")} to rate` +
    (study.training_items ? ` after ${study.training_items} for practice` : "") +
    `, each shown for ${seconds} s`;
  item.append(link, facts);
  return item;
}

async function listOpenStudies() {
  const status = document.getElementById("open-status");
  const list = document.getElementById("open-studies");
  try {
    const response = await fetch("/api/study/open");
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    const studies = await response.json();
    list.replaceChildren(...studies.map(studyEntry));
    list.hidden = studies.length === 0;
    status.textContent = studies.length
      ? `${plural(studies.length, "study")} ${studies.length === 1 ? "is" : "are"} open. Choose one to take part:`
      : "No study is open right now. If an organiser sent you a link, please open that link.";
  } catch (error) {
    status.textContent = `The list of studies could not be loaded (${error.message}). Please reload the page.`;
  }
}

document.addEventListener("DOMContentLoaded", listOpenStudies);
