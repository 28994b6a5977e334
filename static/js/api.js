/**
 * The REST API as the demo site uses it: JSON reads, frame URLs, readable error messages.
 *
 * Every frame URL is built in one place (`frameUrl`) with its query parameters in a fixed order, so one slider
 * state always maps to one URL and the browser's HTTP cache can answer repeated states.
 */

/** Render size of the gallery frames: small enough to render in well under a second on one core. */
export const FRAME_SIZE = Object.freeze({ width: 480, height: 270 });

/** An API answer that was not 2xx, with the server's message. */
export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.name = "ApiError";
    this.status = status;
  }
}

/** The message of an error body: the API's `{"detail": "<field>: <message>", "field"}`. */
export function errorMessage(status, body) {
  const detail = body && typeof body === "object" ? body.detail : null;
  return typeof detail === "string" && detail ? detail : `HTTP ${status}`;
}

/** Throw an `ApiError` for a non-2xx `response`; return it otherwise. */
export async function checked(response) {
  if (response.ok) return response;
  let body = null;
  try {
    body = await response.json();
  } catch {
    body = null;
  }
  throw new ApiError(response.status, errorMessage(response.status, body));
}

/** GET a JSON document. */
export async function getJson(path, { signal } = {}) {
  const response = await checked(await fetch(path, { signal, headers: { Accept: "application/json" } }));
  return response.json();
}

/** The illusion registry: a list of {name, category, description, parameters, severity}. */
export async function illusions() {
  return (await getJson("/api/illusions")).data;
}

/** Summaries of the stored cases of one illusion type. */
export async function casesOfType(type, { signal } = {}) {
  const body = await getJson(`/api/cases?type=${encodeURIComponent(type)}`, { signal });
  return body.data;
}

/** The stored case (its JSON document) with id `id`. */
export async function caseDocument(id, { signal } = {}) {
  return (await getJson(`/api/cases/${encodeURIComponent(id)}`, { signal })).case;
}

/**
 * The URL of frame `frame` of case `id`: JPEG at `FRAME_SIZE`, overlay on or off, optional severity and sun
 * overrides (left out when `undefined`, so an untouched control shares the case's own cached render).
 */
export function frameUrl(id, { frame = 0, overlay = false, severity, sunAzimuth, sunAltitude } = {}) {
  const query = new URLSearchParams({
    width: String(FRAME_SIZE.width),
    height: String(FRAME_SIZE.height),
    overlay: overlay ? "true" : "false",
  });
  if (severity !== undefined) query.set("severity", String(severity));
  if (sunAzimuth !== undefined) query.set("sun_azimuth", String(sunAzimuth));
  if (sunAltitude !== undefined) query.set("sun_altitude", String(sunAltitude));
  return `/api/cases/${encodeURIComponent(id)}/frames/${frame}.jpg?${query}`;
}
