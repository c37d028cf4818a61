// tessera regress report: exposure, zoom, the test/reference wipe, the sortable summary, and
// (with #selftest in the address) a check of the page that a headless browser prints.
"use strict";

// Exposure in whole stops: each render has a PNG per stop (test.png at 0, test.ev+1.png, ...),
// tone-mapped by tessera from the linear image, so no precision is lost in the browser.
function setExposure(stops) {
  document.getElementById("exposure-value").textContent = (stops >= 0 ? "+" : "") + stops + " EV";
  for (const img of document.querySelectorAll("img[data-stem]")) {
    img.src = img.dataset.folder + img.dataset.stem + exposureSuffix(stops);
  }
}

// The wipe: reference on the left of the split, test on the right; a click shows either whole.
function setWipe(figure, percent) {
  figure.querySelector("img.test").style.clipPath = "inset(0 0 0 " + percent + "%)";
  figure.querySelector(".wipe-slider").value = percent;
  figure.querySelector(".which").textContent =
    percent <= 0 ? "test" : percent >= 100 ? "reference" : "reference | test";
}

// Sort the summary by column `index`: numbers by value (missing values last), text by name.
function sortSummary(index, ascending) {
  const table = document.getElementById("summary");
  const rows = Array.from(table.tBodies[0].rows);
  const numeric = table.tHead.rows[0].cells[index].dataset.type === "number";
  const key = (row) => row.cells[index].dataset.value;
  rows.sort((a, b) => {
    if (!numeric) return (ascending ? 1 : -1) * key(a).localeCompare(key(b));
    const x = key(a) === "" ? NaN : Number(key(a));
    const y = key(b) === "" ? NaN : Number(key(b));
    if (Number.isNaN(x) || Number.isNaN(y)) return Number.isNaN(x) - Number.isNaN(y);
    return ascending ? x - y : y - x;
  });
  for (const row of rows) table.tBodies[0].appendChild(row);
  for (const th of table.tHead.rows[0].cells) th.classList.remove("sorted-up", "sorted-down");
  table.tHead.rows[0].cells[index].classList.add(ascending ? "sorted-up" : "sorted-down");
}

// Whether the summary is in order by column `index`.
function isSorted(index, ascending) {
  const table = document.getElementById("summary");
  const numeric = table.tHead.rows[0].cells[index].dataset.type === "number";
  const values = Array.from(table.tBodies[0].rows, (row) => row.cells[index].dataset.value);
  for (let i = 1; i < values.length; i++) {
    const [a, b] = [values[i - 1], values[i]];
    if (numeric) {
      if (b === "") continue;
      if (a === "" || (ascending ? Number(a) > Number(b) : Number(a) < Number(b))) return false;
    } else if ((ascending ? 1 : -1) * a.localeCompare(b) > 0) {
      return false;
    }
  }
  return true;
}

// The file suffix of exposure `stops`.
function exposureSuffix(stops) {
  return stops === 0 ? ".png" : ".ev" + (stops > 0 ? "+" : "") + stops + ".png";
}

// For the self-test: every render's PNG at every other exposure, as hidden images, added while
// the page is parsed so that its load event waits for them.
function probeExposures() {
  const exposure = document.getElementById("exposure");
  const probes = document.createElement("div");
  probes.hidden = true;
  for (const img of document.querySelectorAll("img[data-stem]")) {
    for (let stops = Number(exposure.min); stops <= Number(exposure.max); stops++) {
      if (stops === 0) continue;
      const probe = new Image();
      probe.src = img.dataset.folder + img.dataset.stem + exposureSuffix(stops);
      probes.appendChild(probe);
    }
  }
  document.body.appendChild(probes);
}

// The page's own check, for a headless browser: every image loaded (the exposure probes too),
// one summary row and one section per case, every column sorts; then the worst-first order is
// put back.
function selfTest() {
  const images = Array.from(document.images);
  const loaded = images.filter((img) => img.complete && img.naturalWidth > 0).length;
  const cases = Number(document.body.dataset.cases);
  const columns = document.getElementById("summary").tHead.rows[0].cells.length;
  let sorts = true;
  for (let c = 0; c < columns; c++) {
    for (const ascending of [true, false]) {
      sortSummary(c, ascending);
      sorts = sorts && isSorted(c, ascending);
    }
  }
  sortSummary(0, true);
  const report = {
    images: images.length,
    loaded: loaded,
    cases: cases,
    rows: document.getElementById("summary").tBodies[0].rows.length,
    sections: document.querySelectorAll("section.case").length,
    sorts: sorts,
  };
  const out = document.getElementById("selftest");
  out.textContent = JSON.stringify(report);
  out.dataset.done = "yes";
}

if (location.hash === "#selftest") probeExposures();

window.addEventListener("load", () => {
  const exposure = document.getElementById("exposure");
  exposure.addEventListener("input", () => setExposure(Number(exposure.value)));
  setExposure(Number(exposure.value));
  const zoom = document.getElementById("zoom");
  zoom.addEventListener("change", () => document.documentElement.style.setProperty("--zoom", zoom.value));
  document.documentElement.style.setProperty("--zoom", zoom.value);
  for (const figure of document.querySelectorAll("figure.compare")) {
    const slider = figure.querySelector(".wipe-slider");
    slider.addEventListener("input", () => setWipe(figure, Number(slider.value)));
    figure.querySelector(".wipe").addEventListener("click", () =>
      setWipe(figure, Number(slider.value) > 0 ? 0 : 100));
    setWipe(figure, Number(slider.value));
  }
  const heads = document.getElementById("summary").tHead.rows[0].cells;
  for (let c = 0; c < heads.length; c++) {
    heads[c].addEventListener("click", () => sortSummary(c, !heads[c].classList.contains("sorted-up")));
  }
  if (location.hash === "#selftest") selfTest();
});
