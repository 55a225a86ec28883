// A page this browser holds no valid token for (a link copied from another computer's page, or a
// server restarted with a new token): a form under the banner takes the address the server printed,
// checks its token with the server, keeps it (token.js) and opens the page again at the same link,
// so the machine and the instant the link names are not lost.

import { keepToken, tokenIn } from "./token.js";
import { setText } from "./dom.js";

export class AccessForm {
  /** @param {HTMLFormElement} form holding an input, a submit button and an `.access-error` line */
  constructor(form) {
    this.form = form;
    this.input = form.querySelector("input");
    this.error = form.querySelector(".access-error");
    form.addEventListener("submit", (e) => {
      e.preventDefault();
      this.submit();
    });
  }

  /** Show the form while the server refuses this page's token (or the page has none). */
  show(refused) {
    if (refused === !this.form.hidden) return;
    this.form.hidden = !refused;
    if (refused) setText(this.error, "");
  }

  async submit() {
    const token = tokenIn(this.input.value);
    if (!token) {
      setText(this.error, "That holds no token: paste the whole address the server printed (…/?token=…).");
      return;
    }
    let answer;
    try {
      answer = await fetch("/api/session", { credentials: "omit", cache: "no-store",
        headers: { Authorization: "Bearer " + token } });
    } catch (err) {
      setText(this.error, "The server could not be reached.");
      return;
    }
    if (!answer.ok) {
      setText(this.error, answer.status === 401
        ? "Not this server's token: it prints a new one each time it starts; paste the address it printed last."
        : `The server refused it (${answer.status}).`);
      return;
    }
    keepToken(token);
    location.reload(); // the address keeps the link's machine and instant
  }
}
