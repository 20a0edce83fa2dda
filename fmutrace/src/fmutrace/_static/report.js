/* index.html: filter (status, FMU, model, text) and sort of the cases' rows; offline, no server */
(function () {
  "use strict";
  var table = document.getElementById("cases");
  var body = table.tBodies[0];
  var rows = Array.prototype.slice.call(body.rows);
  var status = document.getElementById("f-status");
  var fmu = document.getElementById("f-fmu");
  var model = document.getElementById("f-model");
  var words = document.getElementById("f-text");
  var shown = document.getElementById("shown");

  function keeps(row) {
    var s = status.value;
    var q = words.value.trim().toLowerCase();
    return (!s || (s === "!pass" ? row.dataset.status !== "pass" : row.dataset.status === s)) &&
      (!fmu.value || row.dataset.fmu === fmu.value) &&
      (!model.value || row.dataset.model === model.value) &&
      (!q || row.textContent.toLowerCase().indexOf(q) >= 0);
  }

  function filter() {
    var n = 0;
    rows.forEach(function (row) {
      row.hidden = !keeps(row);
      n += row.hidden ? 0 : 1;
    });
    shown.textContent = n + " of " + rows.length + " cases shown";
  }

  function sortBy(th) {
    var column = th.cellIndex;
    var numeric = th.dataset.sort === "number";
    var descending = th.getAttribute("aria-sort") === "ascending";
    Array.prototype.forEach.call(th.parentNode.cells, function (cell) { cell.removeAttribute("aria-sort"); });
    th.setAttribute("aria-sort", descending ? "descending" : "ascending");
    var keyed = rows.map(function (row, index) {
      var cell = row.cells[column].textContent;
      return { row: row, key: numeric ? parseFloat(cell) : cell.toLowerCase(), index: index };
    });
    keyed.sort(function (a, b) {
      var order = a.key < b.key ? -1 : a.key > b.key ? 1 : a.index - b.index;
      return descending ? -order : order;
    });
    rows = keyed.map(function (k) { body.appendChild(k.row); return k.row; });
  }

  [status, fmu, model].forEach(function (e) { e.addEventListener("change", filter); });
  words.addEventListener("input", filter);
  Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th) {
    th.addEventListener("click", function () { sortBy(th); });
  });
  filter();
}());
