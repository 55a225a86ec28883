// A worker: who holds the lease of the machine shown, asked every beat off the page's main thread,
// and, while this page holds it, the heartbeat itself (lease.js). A page whose main thread is busy
// (a 3D view drawn in software starves its timers for seconds) still learns at once that its first
// control took the lease and beats on time, so the deadman fires when the page is gone or cut off,
// not when it is merely slow.
//
// Messages in: {lease, beat, headers, every} watches a machine (GET `lease`, or POST `beat` while
// the last answer said this page holds it, every `every` ms, one request at a time); {lease: null}
// stops; {now: true} asks at once ({now: true, yours}: the page just took or gave up the lease). Out: {status, body, beat} of each answer ({status: 0} when the
// server is unreachable; `beat`: it answered a heartbeat).

let watch = null; // {lease, beat, headers, every} of the machine shown
let yours = false; // the last answer said this page holds the lease
let timer = null;
let busy = false;

onmessage = (message) => {
  if (message.data.now) {
    if (typeof message.data.yours === "boolean") yours = message.data.yours;
    if (watch) ask(watch);
    return;
  }
  watch = message.data.lease ? message.data : null;
  yours = false;
  if (watch) ask(watch);
  else clearTimeout(timer);
};

async function ask(current) {
  clearTimeout(timer);
  if (busy) return; // the answer in flight schedules the next ask
  busy = true;
  const beat = yours;
  let answer;
  try {
    const response = await fetch(beat ? current.beat : current.lease,
      { method: beat ? "POST" : "GET", headers: current.headers, credentials: "omit", cache: "no-store" });
    answer = { status: response.status, body: await response.json().catch(() => null), beat };
  } catch (err) {
    answer = { status: 0, body: null, beat };
  }
  busy = false;
  if (watch !== current) { // another machine meanwhile: that answer is stale
    if (watch) ask(watch);
    return;
  }
  yours = answer.status === 200 && Boolean(answer.body?.yours);
  postMessage(answer);
  timer = setTimeout(() => ask(current), current.every);
}
