'use strict';
// The checks that run inside the page (handed to page.evaluate), for check.js.

// ---------------------------------------------------------------------------------------------
// Code evaluated inside the page. Each function returns a list of problem strings.
// `describe` is defined inside each so that the functions are self-contained for page.evaluate.

const PAGE_HELPERS = `
  window.__bc = {};
  __bc.describe = function (el) {
    if (!el) return '(none)';
    const tag = el.localName;
    let s = tag;
    if (el.id) s += '#' + el.id;
    else if (el.classList && el.classList.length) s += '.' + Array.from(el.classList).join('.');
    if (el.classList && el.classList.contains('eq')) {
      if (el.querySelector('.eqno')) s += ' ' + el.querySelector('.eqno').textContent.trim();
      else s += ' "' + __bc.snippet(el, 30) + '"';
    }
    if (el.localName === 'table' && el.caption) {
      const c = el.caption.textContent.replace(/\s+/g, ' ').trim();
      s += ' "' + (c.length > 40 ? c.slice(0, 40) + '…' : c) + '"';
    }
    if (!el.id) {
      // Nearest ancestor with an id, for orientation.
      let a = el.parentElement;
      while (a && !a.id) a = a.parentElement;
      if (a) s += ' in ' + a.localName + '#' + a.id;
    }
    return s;
  };
  __bc.closedDetails = function (el) {
    for (let a = el.parentElement; a; a = a.parentElement) {
      if (a.localName === 'details' && !a.open) return a;
    }
    return null;
  };
  __bc.displayNoneAncestor = function (el) {
    for (let a = el; a; a = a.parentElement) {
      if (getComputedStyle(a).display === 'none') return a;
    }
    return null;
  };
  __bc.snippet = function (el, n) {
    const t = (el.textContent || '').replace(/\\s+/g, ' ').trim();
    return t.length > n ? t.slice(0, n) + '…' : t;
  };
`;

function pageMathProblems() {
  const out = [];
  const maths = Array.from(document.querySelectorAll('math'));
  document.querySelectorAll('merror').forEach((e) => {
    const m = e.closest('math');
    const idx = m ? maths.indexOf(m) + 1 : 0;
    out.push(
      `merror element in math #${idx} (${__bc.describe(m || e)}): "${__bc.snippet(e, 60)}"`
    );
  });
  maths.forEach((m, i) => {
    const r = m.getBoundingClientRect();
    if (r.width > 0 && r.height > 0) return;
    const eq = m.closest('.eq');
    const no = eq && eq.querySelector('.eqno') ? ' ' + eq.querySelector('.eqno').textContent.trim() : '';
    out.push(
      `math #${i + 1}${no} (${__bc.describe(m)}, ${m.getAttribute('display') || 'inline'}) ` +
        `renders ${r.width.toFixed(1)}x${r.height.toFixed(1)} px: "${__bc.snippet(m, 40)}"`
    );
  });
  return out;
}

function pageFigureNameProblems() {
  const out = [];
  const textOf = (el) => (el.textContent || '').replace(/\s+/g, ' ').trim();
  function nameOf(el) {
    // Returns [name, how] or [null, reason].
    const ids = (el.getAttribute('aria-labelledby') || '').trim();
    if (ids) {
      const parts = [];
      for (const id of ids.split(/\s+/)) {
        const ref = document.getElementById(id);
        if (!ref) return [null, `aria-labelledby points at missing id "${id}"`];
        const t = textOf(ref);
        if (!t) return [null, `aria-labelledby points at #${id}, which has no text`];
        parts.push(t);
      }
      return [parts.join(' '), 'aria-labelledby'];
    }
    const label = (el.getAttribute('aria-label') || '').trim();
    if (label) return [label, 'aria-label'];
    if (el.localName === 'svg') {
      const title = Array.from(el.children).find((c) => c.localName === 'title');
      if (title && textOf(title)) return [textOf(title), 'title'];
    }
    if (el.localName === 'img' && (el.getAttribute('alt') || '').trim()) return [el.alt, 'alt'];
    return [null, 'no aria-labelledby, aria-label or <title>'];
  }
  document.querySelectorAll('figure').forEach((fig, i) => {
    const figName = fig.id ? `figure#${fig.id}` : `figure #${i + 1}`;
    const img = fig.querySelector('svg, img, canvas');
    if (!img) {
      out.push(`${figName}: no <svg>, <img> or <canvas> inside`);
      return;
    }
    // Candidates: the image and every element between it and the figure.
    const candidates = [];
    for (let a = img; a && a !== fig; a = a.parentElement) candidates.push(a);
    const reasons = [];
    for (const c of candidates) {
      const role = (c.getAttribute('role') || '').trim().split(/\s+/)[0];
      const isImg = role === 'img' || (c.localName === 'img' && !role);
      if (!isImg) continue;
      const [name, how] = nameOf(c);
      if (name) return; // this figure is fine
      reasons.push(`${__bc.describe(c)} has role="img" but ${how}`);
    }
    if (reasons.length) {
      out.push(`${figName}: image has no accessible name (${reasons.join('; ')})`);
    } else {
      out.push(
        `${figName}: neither its <${img.localName}> nor the element wrapping it ` +
          `(${candidates.slice(1).map(__bc.describe).join(', ') || 'none'}) has role="img"`
      );
    }
  });
  return out;
}

function pageFontProblems() {
  const out = [];
  document.fonts.forEach((f) => {
    if (f.status === 'error') out.push(`font face "${f.family}" failed to load`);
  });
  return out;
}

function pagePrintProblems() {
  const out = [];
  const els = document.querySelectorAll('figure, figcaption, table, .eq');
  els.forEach((el) => {
    const r = el.getBoundingClientRect();
    const visible =
      (typeof el.checkVisibility !== 'function' ||
        el.checkVisibility({ visibilityProperty: true, contentVisibilityAuto: false })) &&
      r.width > 0 &&
      r.height > 0;
    if (visible) return;
    let why;
    const d = __bc.closedDetails(el);
    const dn = __bc.displayNoneAncestor(el);
    if (d) why = `inside closed <details${d.className ? ' class="' + d.className + '"' : ''}>`;
    else if (dn) why = dn === el ? 'display: none' : `ancestor ${__bc.describe(dn)} has display: none`;
    else if (getComputedStyle(el).visibility !== 'visible') why = 'visibility: ' + getComputedStyle(el).visibility;
    else why = `rendered ${r.width.toFixed(0)}x${r.height.toFixed(0)} px`;
    // A figcaption inside an already reported figure adds nothing.
    if (el.localName === 'figcaption' && el.closest('figure')) {
      const fr = el.closest('figure').getBoundingClientRect();
      if (fr.width === 0 || fr.height === 0) return;
    }
    out.push(`${__bc.describe(el)}: hidden in print (${why})`);
  });
  return out;
}

function pageSidewaysScroll(label) {
  const se = document.scrollingElement;
  const sw = se.scrollWidth;
  const cw = se.clientWidth;
  if (sw <= cw + 1) return [];
  // Find the outermost elements that stick out past the right edge and are not clipped by a
  // scroll box (overflow-x other than visible) between them and the page.
  const culprits = [];
  const clipsX = (el) => {
    const o = getComputedStyle(el).overflowX;
    return o !== 'visible';
  };
  const walk = (el) => {
    for (const c of el.children) {
      const r = c.getBoundingClientRect();
      const right = r.right + window.scrollX;
      if (right > cw + 1 && r.width > 0) {
        // Does a descendant stick out further? Report the outermost element only if it is itself
        // wider than the page, otherwise descend to find who pushes it.
        if (r.width > cw + 1 || c.children.length === 0 || clipsX(c)) {
          culprits.push([c, right]);
          continue;
        }
      }
      if (!clipsX(c)) walk(c);
    }
  };
  walk(document.body);
  const out = [];
  const lines = culprits
    .sort((a, b) => b[1] - a[1])
    .slice(0, 6)
    .map(([c, right]) => `${__bc.describe(c)} reaches x=${right.toFixed(0)}`);
  out.push(
    `page scrolls sideways at ${label} (scrollWidth ${sw} > clientWidth ${cw})` +
      (lines.length ? ': ' + lines.join('; ') : '')
  );
  return out;
}

function pageFigureTextProblems(args) {
  const { minPx, label } = args;
  const out = [];
  document.querySelectorAll('figure').forEach((fig, i) => {
    const figName = fig.id ? `figure#${fig.id}` : `figure #${i + 1}`;
    let smallest = Infinity;
    let smallestText = '';
    let below = 0;
    let total = 0;
    fig.querySelectorAll('svg').forEach((svg) => {
      if (svg.ownerSVGElement) return; // nested svg: handled through its outermost svg
      const rect = svg.getBoundingClientRect();
      if (rect.width === 0) return;
      const vb = svg.viewBox && svg.viewBox.baseVal;
      const vbw = vb && vb.width > 0 ? vb.width : rect.width;
      const scale = rect.width / vbw;
      const svgCtm = svg.getScreenCTM();
      svg.querySelectorAll('text').forEach((t) => {
        const s = (t.textContent || '').trim();
        if (!s) return;
        total++;
        const fs = parseFloat(getComputedStyle(t).fontSize);
        // Transforms between the svg's user space and the text (group transforms, nested svg).
        let inner = 1;
        const ctm = t.getScreenCTM();
        if (ctm && svgCtm) {
          const det = Math.abs(ctm.a * ctm.d - ctm.b * ctm.c);
          const svgDet = Math.abs(svgCtm.a * svgCtm.d - svgCtm.b * svgCtm.c);
          if (svgDet > 0) inner = Math.sqrt(det / svgDet);
        }
        const px = fs * scale * inner;
        if (px < minPx) below++;
        if (px < smallest) {
          smallest = px;
          smallestText = s;
        }
      });
    });
    if (below > 0) {
      out.push(
        `${figName}: ${below} of ${total} text labels render below ${minPx} px at ${label}; ` +
          `smallest ${smallest.toFixed(1)} px ("${smallestText.slice(0, 30)}")`
      );
    }
  });
  return out;
}


module.exports = { PAGE_HELPERS, pageMathProblems, pageFigureNameProblems, pageFontProblems, pagePrintProblems, pageSidewaysScroll, pageFigureTextProblems };
