// A worker: the lease holder's heartbeat (lease.js), off the page's main thread. A page whose main
// thread is busy (a 3D view drawing in software, a long layout) still beats on time, so the
// deadman fires when the page is gone or cut off, not when it is merely slow.
//
// Messages in: {url, headers, every} starts beating (POST url every `every` ms, one request at a
// time), {url: null} stops. Out: {status, body} of each answer ({status: 0} when unreachable).

let beat = null; // {url, headers, every} while beating
let timer = null;

onmessage = (message) => {
  clearTimeout(timer);
  beat = message.data.url ? message.data : null;
  if (beat) send(beat);
};

async function send(current) {
  let answer;
  try {
    const response = await fetch(current.url, { method: "POST", headers: current.headers, credentials: "omit", cache: "no-store" });
    answer = { status: response.status, body: await response.json().catch(() => null) };
  } catch (err) {
    answer = { status: 0, body: null };
  }
  if (beat !== current) return; // stopped or restarted meanwhile: that answer is stale
  postMessage(answer);
  timer = setTimeout(() => send(current), current.every);
}
