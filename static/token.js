// The access token this page holds. The server prints the dashboard's address with ?token=...;
// the page takes it from there once, keeps it in sessionStorage (per origin, so per port: two
// dashboards on two ports of one host never share or overwrite it) and drops it from the
// address bar. It is sent as a Bearer header and as a websocket subprotocol; there is no cookie,
// which every other server on the same host would receive.

const KEY = "fsmscope.token";

function takeToken() {
  const url = new URL(location.href);
  const given = url.searchParams.get("token");
  if (given !== null) {
    sessionStorage.setItem(KEY, given);
    url.searchParams.delete("token");
    history.replaceState(history.state, "", url.pathname + url.search + url.hash);
  }
  return sessionStorage.getItem(KEY);
}

export const token = takeToken();

/** Headers that authenticate a fetch. */
export function authHeaders() {
  return token ? { Authorization: "Bearer " + token } : {};
}

/** Websocket subprotocols that authenticate a stream (the server answers with "fsmscope"). */
export function streamProtocols() {
  return token ? ["fsmscope", "fsmscope.token." + token] : ["fsmscope"];
}
