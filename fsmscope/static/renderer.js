// When the page draws its state (store.js). Events, and a replay playing, are drawn at most 30 times
// a second, and no more often than leaves drawing a quarter of the main thread (frame_pace.js: a big
// machine drawn open draws less often); at most 4 times a second while the page looks back and only
// its count of events behind changes. What the user does is drawn at the next frame.
//
// A drawing is a few frames, one after the other (app.js: the machine, then the log and the
// userdata): each half of a big machine's drawing under a flood stays under 50 ms, where the whole
// was a long task that kept the page from answering the user (bench/big_machine_browser.py).

import { FramePace } from "./frame_pace.js";

export const PACED_FRAME_MS = 33;
export const BEHIND_FRAME_MS = 250;

export class Renderer {
  /**
   * @param {Store} store the page's store: its state is what each frame draws
   * @param {Array<(state: object) => void>} frames what each animation frame of a drawing draws, in order
   */
  constructor(store, frames) {
    this.store = store;
    this.frames = frames;
    this.pace = new FramePace();
    this.queued = false;
    this.timer = null;
    this.last = -Infinity;
    // A drawing's first frame, by this name: bench/timetravel_browser.py times the frames called so.
    const render = () => this._draw(0);
    this.render = render;
  }

  /** Draw at the next animation frame, or, `paced`, not sooner than the pace allows. */
  queue(paced = false) {
    if (this.queued && (this.timer === null || paced)) return;
    clearTimeout(this.timer);
    this.timer = null;
    this.queued = true;
    const { past, playing } = this.store.state.instant;
    const gap = past && !playing ? BEHIND_FRAME_MS : this.pace.gap(PACED_FRAME_MS);
    const wait = paced ? this.last + gap - performance.now() : 0;
    if (wait <= 0) {
      requestAnimationFrame(this.render);
      return;
    }
    this.timer = setTimeout(() => {
      this.timer = null;
      requestAnimationFrame(this.render);
    }, wait);
  }

  _draw(i) {
    if (i === 0) {
      this.queued = false;
      this.last = performance.now();
      this.pace.started();
    } else {
      this.pace.frame();
    }
    this.frames[i](this.store.state);
    if (i + 1 < this.frames.length) requestAnimationFrame(() => this._draw(i + 1));
  }
}
