// The timeline of the machine shown, asked of the server (GET .../timeline) for the range the
// timeline shows (timeline.js), and asked again every second while a live run grows: one question
// at a time (an answer the server delays, for this page's budget of its time, is not asked again
// meanwhile), the newest range asked once the one in flight is answered.

const REFRESH_MS = 1000; // a live machine's timeline is asked again this often

export class TimelineLoader {
  /**
   * @param {Store} store the page's store (store.js): the machine shown, whether it is a replay
   * @param {object} api the REST API (api.js): timeline(name, range)
   * @param {Timeline} timeline what draws it (timeline.js)
   */
  constructor(store, api, timeline) {
    this.store = store;
    this.api = api;
    this.timeline = timeline;
    this.range = { since_t: null, until_t: null }; // null: the whole run
    this.asking = false;
    this.again = false; // asked meanwhile: ask once more when the answer comes
    setInterval(() => {
      if (!this.store.state.instant.replay && !document.hidden) this.load(); // a live run grows
    }, REFRESH_MS);
  }

  /** Another machine is shown: its whole run. */
  open() {
    this.setRange({ since_t: null, until_t: null });
  }

  /** The timeline shows `range` ({since_t, until_t}, null: the whole run) now. */
  setRange(range) {
    this.range = range;
    this.load();
  }

  async load() {
    const name = this.store.state.name;
    if (name === null) return;
    if (this.asking) {
      this.again = true;
      return;
    }
    this.asking = true;
    const range = this.range;
    try {
      const data = await this.api.timeline(name, range);
      if (name === this.store.state.name && range === this.range) this.timeline.setData(data);
    } catch (err) {
      if (name === this.store.state.name) this.store.say("Could not read the timeline: " + (err.detail || err.message), "warn");
    } finally {
      this.asking = false;
    }
    if (this.again) {
      this.again = false;
      this.load();
    }
  }
}
