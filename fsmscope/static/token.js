// The access token this page holds. The server prints the dashboard's address with ?token=...;
// the page takes it from there once, keeps it in sessionStorage (per origin, so per port: two
// dashboards on two ports of one host never share or overwrite it) and drops it from the
// address bar. It is sent as a Bearer header and as a websocket subprotocol; there is no cookie,
// which every other server on the same host would receive.
//
// A link copied from the page holds no token (deeplink.js), so the token is also kept in this
// origin's localStorage: a new tab of the same browser opening such a link takes the token the
// browser was last given for this dashboard, and keeps it for itself from then on. Elsewhere the
// link asks for the printed address (access.js). A server prints a new token each run, so what is
// kept opens nothing after a restart.

const KEY = "fsmscope.token";

/** Keep `value` as this tab's token, and as the one this browser's next tabs on this origin take. */
export function keepToken(value) {
  sessionStorage.setItem(KEY, value);
  localStorage.setItem(KEY, value);
}

function takeToken() {
  const url = new URL(location.href);
  const given = url.searchParams.get("token");
  if (given !== null) {
    keepToken(given);
    url.searchParams.delete("token");
    history.replaceState(history.state, "", url.pathname + url.search + url.hash);
  }
  const own = sessionStorage.getItem(KEY);
  if (own !== null) return own;
  const kept = localStorage.getItem(KEY);
  if (kept !== null) sessionStorage.setItem(KEY, kept); // this tab's from now on, whatever later tabs are given
  return kept;
}

export const token = takeToken();

/** The token in `text`: a dashboard's address with ?token=..., or a bare token; null when it holds none. */
export function tokenIn(text) {
  const given = text.trim();
  try {
    return new URL(given).searchParams.get("token");
  } catch (err) {
    return /^[A-Za-z0-9_-]{16,}$/.test(given) ? given : null; // what secrets.token_urlsafe makes
  }
}

/** Headers that authenticate a fetch. */
export function authHeaders() {
  return token ? { Authorization: "Bearer " + token } : {};
}

/** Websocket subprotocols that authenticate a stream (the server answers with "fsmscope"). */
export function streamProtocols() {
  return token ? ["fsmscope", "fsmscope.token." + token] : ["fsmscope"];
}
