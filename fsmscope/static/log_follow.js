// Whether the event log follows its newest row: only the user's own scrolling (wheel, touch, a
// scrolling key, the scrollbar) takes it away from the end, and bringing it back there follows again.

// Only the user's own scrolling stops the log following the newest row: a scroll within this long of
// their wheel, touch or scrolling key, or while they hold the pointer down (the scrollbar). A scroll
// of the page's own lands short of the end when the blocks it scrolled past get their real heights
// (style.css): taken for the user's, it stopped the log following after every search.
const USER_SCROLL_MS = 400;
const SCROLL_KEYS = new Set(["ArrowUp", "ArrowDown", "PageUp", "PageDown", "Home", "End", " "]);
const UP_KEYS = new Set(["ArrowUp", "PageUp", "Home"]);

/** Call `setStick(false)` when the user scrolls `host` (the log) away from its end, `setStick(true)`
 * when a scroll brings it back there. */
export function followUserScrolls(host, setStick) {
  let userAt = -Infinity; // when the user last scrolled by wheel, touch or key
  let pointerDown = false;
  // The user went up with a wheel or a key: no scroll reaching the end follows again until they go
  // down (a scroll event of the page's own, dispatched after their wheel, once did).
  let leftByUser = false;
  const byUser = () => {
    userAt = performance.now();
    leftByUser = false;
  };
  // Up, when there is room above: the user leaves the end at once, however late (a loaded page)
  // the scroll events of their wheel or key come.
  const upByUser = () => {
    userAt = performance.now();
    if (host.scrollTop > 0) {
      leftByUser = true;
      setStick(false);
    }
  };
  host.addEventListener("wheel", (e) => (e.deltaY < 0 ? upByUser() : byUser()), { passive: true });
  host.addEventListener("touchmove", byUser, { passive: true });
  document.addEventListener("keydown", (e) => {
    if (!SCROLL_KEYS.has(e.key) || e.target.closest?.("input, textarea, select")) return;
    if (UP_KEYS.has(e.key) && host.contains(document.activeElement)) upByUser();
    else byUser();
  });
  host.addEventListener("pointerdown", () => {
    pointerDown = true;
    leftByUser = false;
  });
  for (const type of ["pointerup", "pointercancel"]) {
    window.addEventListener(type, () => {
      if (pointerDown) byUser();
      pointerDown = false;
    });
  }
  let lastTop = host.scrollTop;
  host.addEventListener("scroll", () => {
    const up = host.scrollTop < lastTop; // the first steps of a scroll up may still be near the end
    lastTop = host.scrollTop;
    const byTheUser = pointerDown || performance.now() - userAt < USER_SCROLL_MS;
    if (!up && !leftByUser && host.scrollHeight - host.scrollTop - host.clientHeight < 24) setStick(true);
    else if (byTheUser) setStick(false);
  }, { passive: true });
}
