// The connection badge: the stream's state, its event rate and latency, the events it missed.

import { setText } from "./dom.js";

/**
 * @param {HTMLElement} badge the badge
 * @param {Stream|null} stream the stream of the machine shown (stream.js)
 * @param {object} about {online: whether the server answers, replay: whether the machine is a
 *   recording played again (its timestamps say nothing of latency)}
 */
export function showBadge(badge, stream, { online, replay }) {
  const state = !stream ? "idle" : stream.state;
  let cls = "down";
  let text = state;
  if (state === "live") {
    cls = "live";
    const rate = stream.rate();
    const lat = stream.latencyMs;
    const shownRate = rate < 10 ? rate.toFixed(1) : Math.round(rate);
    if (replay) {
      text = `replay · ${shownRate} ev/s`;
    } else {
      text = `live · ${shownRate} ev/s · ${lat === null ? "–" : lat < 10 ? lat.toFixed(1) : Math.round(lat)} ms`;
    }
  } else if (state === "reconnecting" || state === "connecting") {
    cls = "wait";
    text = online ? state + "…" : "server unreachable · retrying";
  }
  if (stream && stream.missed) text += ` · missed ${stream.missed}`;
  badge.className = "badge " + cls;
  badge.dataset.state = state;
  const label = badge.querySelector(".badge-text");
  setText(label, text);
}
