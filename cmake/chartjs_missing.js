/* kin2grf was built without Chart.js (Debian's libjs-chart.js): a stand-in that writes, in place of
   each plot, where the plots went. The report's tables are complete. */
function Chart(canvas) {
  var p = document.createElement('p');
  p.textContent = 'Plot not drawn: this kin2grf was built without Chart.js (install libjs-chart.js and rebuild).';
  canvas.parentNode.replaceChild(p, canvas);
}
