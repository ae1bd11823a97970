// Every figure of an article opens full size: an image that is not already a link is wrapped in a
// link to its own file (reports' three-panel figures are shrunk to the column width).
document.addEventListener("DOMContentLoaded", () => {
  for (const img of document.querySelectorAll(".bd-article img")) {
    if (img.closest("a")) continue;
    const a = document.createElement("a");
    a.href = img.getAttribute("src");
    a.className = "robomech-full-size";
    a.title = "open full size";
    img.replaceWith(a);
    a.appendChild(img);
  }
});
