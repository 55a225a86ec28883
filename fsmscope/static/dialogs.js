// Modal dialogs (preempt confirmation, set-initial-state editor, breakpoint editor) and the context
// menu. Texts go in with textContent; the userdata editor validates its JSON before sending.

import { h } from "./dom.js";

/** Ask to confirm a preempt; resolves to {reason} or null when cancelled. */
export function confirmPreempt(machine) {
  const dialog = document.getElementById("preempt-dialog");
  dialog.querySelector(".dlg-machine").textContent = machine;
  const reason = dialog.querySelector("input[name=reason]");
  return new Promise((resolve) => {
    dialog.addEventListener("close", () => {
      resolve(dialog.returnValue === "confirm" ? { reason: reason.value.trim() } : null);
    }, { once: true });
    dialog.returnValue = "";
    dialog.showModal();
    dialog.querySelector("#preempt-confirm").focus();
  });
}

/** Parse the editor's text: a JSON object, or an error message. */
function parseUserdata(text) {
  if (!text.trim()) return { value: {} };
  let value;
  try {
    value = JSON.parse(text);
  } catch (err) {
    return { error: "Not valid JSON: " + err.message };
  }
  if (value === null || typeof value !== "object" || Array.isArray(value)) {
    return { error: "Userdata must be a JSON object ({\"key\": value, ...})." };
  }
  return { value };
}

/**
 * Show the modal `dialog` (a <form method="dialog"> with a button value="send" and a .dlg-error)
 * until it is cancelled or `submit` succeeds. `read()` gives the form's {value} or an {error}
 * (shown, and "send" disabled), after every input. A rejected `submit(value)` shows its message and
 * leaves the dialog open to be corrected. Enter in a one-line field sends, never cancels.
 * @returns {Promise<boolean>} true when `submit` succeeded
 */
function formDialog(dialog, read, submit) {
  const form = dialog.querySelector("form");
  const error = dialog.querySelector(".dlg-error");
  const send = dialog.querySelector("button[value=send]");
  const check = () => {
    const parsed = read();
    error.textContent = parsed.error || "";
    send.disabled = Boolean(parsed.error);
    return parsed;
  };
  check();
  return new Promise((resolve) => {
    const onKey = (e) => {
      if (e.key !== "Enter" || e.target.localName !== "input") return;
      e.preventDefault();
      if (!send.disabled) form.requestSubmit(send);
    };
    const onSubmit = async (e) => {
      if (e.submitter?.value !== "send") return; // cancel: let the dialog close
      e.preventDefault();
      const parsed = check();
      if (parsed.error) return;
      send.disabled = true;
      try {
        await submit(parsed.value);
        finish(true);
        dialog.close();
      } catch (err) {
        error.textContent = err.message || String(err);
        send.disabled = false;
      }
    };
    const onClose = () => finish(false);
    let done = false;
    const finish = (ok) => {
      if (done) return;
      done = true;
      form.removeEventListener("input", check);
      form.removeEventListener("keydown", onKey);
      form.removeEventListener("submit", onSubmit);
      dialog.removeEventListener("close", onClose);
      resolve(ok);
    };
    form.addEventListener("input", check);
    form.addEventListener("keydown", onKey);
    form.addEventListener("submit", onSubmit);
    dialog.addEventListener("close", onClose);
    dialog.showModal();
  });
}

/**
 * The set-initial-state editor.
 * @param {object} opts {container, state, userdata, submit(userdata) -> Promise (rejects with an Error whose message is shown)}
 * @returns {Promise<boolean>} true when the server accepted it
 */
export function editInitialState({ container, state, userdata, submit }) {
  const dialog = document.getElementById("initial-dialog");
  const area = dialog.querySelector("textarea");
  dialog.querySelector(".dlg-what").textContent = `Start ${container} in state ${state}`;
  area.value = JSON.stringify(userdata || {}, null, 2);
  const read = () => {
    const parsed = parseUserdata(area.value);
    area.classList.toggle("invalid", Boolean(parsed.error));
    return parsed;
  };
  const shown = formDialog(dialog, read, submit);
  area.focus();
  return shown;
}

/**
 * The "Break when…" editor of a breakpoint on the state at `state`: before or after it, after it
 * only with one of its `outcomes` (or any), when a condition holds (or always).
 * @param {object} opts {state, outcomes, submit({state, at, outcome, when}) -> Promise (rejects with an Error whose message, the server's, is shown)}
 * @returns {Promise<boolean>} true when the server accepted it
 */
export function editBreakpoint({ state, outcomes, submit }) {
  const dialog = document.getElementById("break-dialog");
  const form = dialog.querySelector("form");
  const outcome = form.elements.outcome;
  const when = form.elements.when;
  dialog.querySelector(".dlg-what").textContent = state;
  form.elements.at.value = "before";
  outcome.replaceChildren(h("option", { value: "", text: "any" }), ...outcomes.map((o) => h("option", { value: o, text: o })));
  when.value = "";
  const read = () => {
    const at = form.elements.at.value;
    outcome.disabled = at !== "after";
    return { value: { state, at, outcome: at === "after" && outcome.value ? outcome.value : null, when: when.value.trim() || null } };
  };
  const shown = formDialog(dialog, read, submit);
  when.focus();
  return shown;
}

/** A context menu at (x, y) with items [{label, action, disabled, title}]. */
export function showMenu(x, y, title, items) {
  const menu = document.getElementById("menu");
  const head = document.createElement("div");
  head.className = "menu-title";
  head.textContent = title;
  const buttons = items.map((item) => {
    const b = document.createElement("button");
    b.type = "button";
    b.setAttribute("role", "menuitem");
    b.textContent = item.label;
    b.disabled = Boolean(item.disabled);
    if (item.title) b.title = item.title;
    b.addEventListener("click", () => {
      hideMenu();
      item.action();
    });
    return b;
  });
  menu.replaceChildren(head, ...buttons);
  menu.hidden = false;
  const rect = menu.getBoundingClientRect();
  menu.style.left = Math.min(x, innerWidth - rect.width - 4) + "px";
  menu.style.top = Math.min(y, innerHeight - rect.height - 4) + "px";
  setTimeout(() => {
    document.addEventListener("pointerdown", outside, { capture: true });
    document.addEventListener("keydown", escape, { capture: true });
  }, 0);
}

function outside(e) {
  if (!document.getElementById("menu").contains(e.target)) hideMenu();
}

function escape(e) {
  if (e.key === "Escape") hideMenu();
}

function hideMenu() {
  document.getElementById("menu").hidden = true;
  document.removeEventListener("pointerdown", outside, { capture: true });
  document.removeEventListener("keydown", escape, { capture: true });
}
