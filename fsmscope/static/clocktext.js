// How the page writes an instant: local wall-clock time to the millisecond, HH:MM:SS.mmm.

/** `t` (seconds since the epoch, as events carry it) as HH:MM:SS.mmm; "" when it is not a number. */
export function clockText(t) {
  if (typeof t !== "number") return "";
  const d = new Date(t * 1000);
  const pad = (n, w = 2) => String(n).padStart(w, "0");
  return `${pad(d.getHours())}:${pad(d.getMinutes())}:${pad(d.getSeconds())}.${pad(d.getMilliseconds(), 3)}`;
}
