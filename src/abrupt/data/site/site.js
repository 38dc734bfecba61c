// abrupt catalog site: sorting and filtering of the events table (plain JavaScript, works from disk).
(function () {
  "use strict";
  var table = document.getElementById("events");
  if (!table) { return; }
  var body = table.tBodies[0];
  var rows = Array.prototype.slice.call(body.rows);
  var text = document.getElementById("filter-text");
  var selects = Array.prototype.slice.call(document.querySelectorAll("select[data-column]"));
  var count = document.getElementById("shown-count");

  function cellText(row, column) {
    return (row.getAttribute("data-" + column) || "").toLowerCase();
  }

  function apply() {
    var words = (text.value || "").toLowerCase().split(/\s+/).filter(function (w) { return w; });
    var shown = 0;
    rows.forEach(function (row) {
      var ok = selects.every(function (s) { return !s.value || cellText(row, s.getAttribute("data-column")) === s.value.toLowerCase(); });
      var all = row.textContent.toLowerCase();
      ok = ok && words.every(function (w) { return all.indexOf(w) >= 0; });
      row.hidden = !ok;
      if (ok) { shown += 1; }
    });
    count.textContent = shown + " of " + rows.length + " event(s) shown";
  }

  function sortBy(th) {
    var index = th.cellIndex;
    var numeric = th.getAttribute("data-type") === "num";
    var ascending = th.getAttribute("aria-sort") !== "ascending";
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (c) { c.removeAttribute("aria-sort"); });
    th.setAttribute("aria-sort", ascending ? "ascending" : "descending");
    var key = function (row) {
      var cell = row.cells[index];
      var v = cell.getAttribute("data-value");
      if (v === null) { v = cell.textContent; }
      if (numeric) { v = parseFloat(v); return isNaN(v) ? -Infinity : v; }
      return v;
    };
    rows.sort(function (a, b) {
      var x = key(a), y = key(b);
      var c = x < y ? -1 : (x > y ? 1 : 0);
      return ascending ? c : -c;
    });
    rows.forEach(function (row) { body.appendChild(row); });
  }

  Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th) {
    if (th.classList.contains("sortable")) {
      th.addEventListener("click", function () { sortBy(th); });
    }
  });
  text.addEventListener("input", apply);
  selects.forEach(function (s) { s.addEventListener("change", apply); });
  apply();
}());
