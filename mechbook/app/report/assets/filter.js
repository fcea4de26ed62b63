// mechbook report: filter the index's rows by book, outcome and text (no libraries).
"use strict";
(function () {
  const book = document.getElementById("filter-book");
  const status = document.getElementById("filter-status");
  const text = document.getElementById("filter-text");
  const rows = Array.from(document.querySelectorAll("#outcomes tbody tr"));
  const shown = document.getElementById("shown");

  function apply() {
    const b = book.value, s = status.value, t = text.value.trim().toLowerCase();
    let n = 0;
    for (const row of rows) {
      const ok = (!b || row.dataset.book === b) && (!s || row.dataset.status === s) &&
        (!t || row.textContent.toLowerCase().includes(t));
      row.hidden = !ok;
      if (ok) n += 1;
    }
    shown.textContent = String(n);
    const params = new URLSearchParams();
    if (b) params.set("book", b);
    if (s) params.set("status", s);
    if (t) params.set("q", t);
    const query = params.toString();
    try {  // keep the filter in the address, so that a filtered view can be shared
      history.replaceState(null, "", query ? "?" + query : location.pathname);
    } catch (e) {
      // some browsers refuse this for file: pages; the filter works all the same
    }
  }

  const initial = new URLSearchParams(location.search);
  book.value = initial.get("book") || "";
  status.value = initial.get("status") || "";
  text.value = initial.get("q") || "";
  for (const el of [book, status]) el.addEventListener("change", apply);
  text.addEventListener("input", apply);
  apply();
})();
