// Building elements: h(tag, props, ...children), the page's one way to make DOM.
// Every name, value and message goes in as text (createElement + textContent), never as HTML.

export function h(tag, props = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === "class") el.className = v;
    else if (k === "text") el.textContent = v;
    else if (k === "title") el.title = v;
    else if (k.startsWith("data-") || k.startsWith("aria-") || k === "role") el.setAttribute(k, v);
    else el[k] = v;
  }
  for (const child of children) if (child !== null && child !== undefined) el.append(child);
  return el;
}

/** Set `el`'s text only when it changes: a text written again, even the same, is laid out again,
 * and outside a contained pane that is a layout of the whole page at every frame. */
export function setText(el, text) {
  if (el.textContent !== text) el.textContent = text;
}

/**
 * Give `cls` to exactly the elements that `find` returns for `keys`, touching only those that
 * change (a class set again is still a style recalculation, and a frame has many).
 * @param {Set} before the keys marked so far (this function's last answer)
 * @returns {Set} the keys marked now (those `find` found)
 */
export function markExactly(cls, before, keys, find) {
  for (const key of before) {
    if (!keys.has(key)) find(key)?.classList.remove(cls);
  }
  const now = new Set();
  for (const key of keys) {
    const el = find(key);
    if (!el) continue;
    if (!before.has(key)) el.classList.add(cls);
    now.add(key);
  }
  return now;
}
