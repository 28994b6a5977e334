/**
 * The REST API as the demo site uses it: JSON reads, frame and detection URLs, readable error messages.
 *
 * Every frame URL is built in one place (`frameQuery`) with its query parameters in a fixed order, so one slider
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

/** The lane detectors: a list of {name, kind, available, reason, model}. */
export async function detectors() {
  return (await getJson("/api/detectors")).data;
}

/**
 * Query of a frame at `FRAME_SIZE`: the overlay (when given) and detector (when set), then the optional severity
 * and sun overrides (left out when `undefined`, so an untouched control shares the case's own cached render).
 */
function frameQuery({ overlay, detector, severity, sunAzimuth, sunAltitude }) {
  const query = new URLSearchParams({ width: String(FRAME_SIZE.width), height: String(FRAME_SIZE.height) });
  if (overlay !== undefined) query.set("overlay", overlay ? "true" : "false");
  if (detector) query.set("detector", detector);
  if (severity !== undefined) query.set("severity", String(severity));
  if (sunAzimuth !== undefined) query.set("sun_azimuth", String(sunAzimuth));
  if (sunAltitude !== undefined) query.set("sun_altitude", String(sunAltitude));
  return query;
}

/**
 * The URL of frame `frame` of case `id`: JPEG at `FRAME_SIZE`, overlay on or off, a detector's lanes (magenta)
 * when `detector` is set, optional severity and sun overrides.
 */
export function frameUrl(id, { frame = 0, overlay = false, detector = "", severity, sunAzimuth, sunAltitude } = {}) {
  const query = frameQuery({ overlay, detector, severity, sunAzimuth, sunAltitude });
  return `/api/cases/${encodeURIComponent(id)}/frames/${frame}.jpg?${query}`;
}

/** The URL of `detector`'s lanes and TuSimple score on the frame `frameUrl` shows with the same settings. */
export function detectionsUrl(id, { frame = 0, detector, severity, sunAzimuth, sunAltitude }) {
  const query = frameQuery({ detector, severity, sunAzimuth, sunAltitude });
  return `/api/cases/${encodeURIComponent(id)}/frames/${frame}/detections?${query}`;
}

/** The editor's address, opening case `id` there. */
export function editorUrl(id) {
  return `/editor?case=${encodeURIComponent(id)}`;
}
