// How often the page may draw under a flood of events: at most every `minMs`, and never so often
// that drawing takes more than a fifth of the main thread. A drawing is one or more frames; a frame's
// cost is its script and the browser's style, layout and paint of it, timed from the frame's start to
// the first task after it (a MessageChannel message, which runs once the frame is painted). A drawing
// that costs 60 ms (600 states drawn open, bench/big_machine_browser.py) is done at most every
// 300 ms, a small machine's 3 ms ones still 30 times a second. What a user does is drawn at once,
// whatever the pace.

const SHARE = 0.2; // of the main thread that drawing may take under a flood
const SMOOTHING = 0.3; // weight of the newest frame in the cost kept

export class FramePace {
  constructor() {
    this.cost = 0; // ms a drawing costs, smoothed
    this.sum = 0; // ms the frames of the drawing under way have cost so far
    this.startedAt = null;
    this.channel = new MessageChannel();
    this.channel.port1.onmessage = () => {
      if (this.startedAt === null) return;
      this.sum += performance.now() - this.startedAt;
      this.startedAt = null;
    };
  }

  /** A drawing starts (at the start of its first requestAnimationFrame callback): the last one's
   * frames are its cost. */
  started() {
    if (this.sum) this.cost = this.cost ? this.cost + SMOOTHING * (this.sum - this.cost) : this.sum;
    this.sum = 0;
    this.frame();
  }

  /** Another frame of the drawing under way starts. */
  frame() {
    this.startedAt = performance.now();
    this.channel.port2.postMessage(null);
  }

  /** The least time in ms from one frame's start to the next one's, `minMs` or more. */
  gap(minMs) {
    return Math.max(minMs, this.cost / SHARE);
  }
}
