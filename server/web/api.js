// api.js - the page's only way to the service: fetch with the API key of this tab (kept
// in sessionStorage, never in a URL), errors as ApiError carrying the problem+json.

const KEY_ITEM = 'grainpack.apiKey';

export function getKey() {
  return sessionStorage.getItem(KEY_ITEM) || '';
}

export function setKey(key) {
  if (key) sessionStorage.setItem(KEY_ITEM, key);
  else sessionStorage.removeItem(KEY_ITEM);
}

// A refused request: the HTTP status and the service's problem (RFC 9457).
export class ApiError extends Error {
  constructor(status, problem) {
    super(problem.detail || problem.title || `HTTP ${status}`);
    this.status = status;
    this.problem = problem;
  }
}

function authHeaders(extra) {
  const headers = { ...extra };
  const key = getKey();
  if (key) headers.Authorization = `Bearer ${key}`;
  return headers;
}

// Sends a request; resolves to the Response when it is a success, rejects with ApiError
// otherwise (status 0 when the service did not answer). `body` is sent as JSON.
export async function request(path, { method = 'GET', body, accept = 'application/json', signal } = {}) {
  const init = { method, signal, cache: 'no-store', headers: authHeaders({ Accept: accept }) };
  if (body !== undefined) {
    init.headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch(path, init);
  } catch (err) {
    if (err.name === 'AbortError') throw err;
    throw new ApiError(0, { title: 'No answer', detail: `the service did not answer (${err.message})` });
  }
  if (response.ok) return response;
  let problem;
  try {
    problem = await response.json();
  } catch {
    problem = { title: response.statusText, detail: `HTTP ${response.status} ${response.statusText}` };
  }
  throw new ApiError(response.status, problem);
}

export async function getJSON(path, options) {
  return (await request(path, options)).json();
}

// What to tell the reader about a failed request, in one sentence.
export function describe(err) {
  if (!(err instanceof ApiError)) return String(err.message || err);
  const detail = err.problem.detail || err.message;
  if (err.status === 401) {
    return getKey()
      ? `Your API key was refused: ${detail}. Check it, or ask the service's administrator.`
      : `This service needs an API key: enter yours at the top of the page. (${detail})`;
  }
  if (err.status === 403) return `Your API key may not do this: ${detail}`;
  if (err.status === 0) return `The service did not answer: is grainpackd still running? (${detail})`;
  return detail;
}

// Fetches a result as a Blob (with the key), for pictures and downloads.
export async function getBlob(path, accept = '*/*') {
  return (await request(path, { accept })).blob();
}
