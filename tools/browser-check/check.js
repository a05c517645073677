#!/usr/bin/env node
// Browser check of the accelcal report: opens one self-contained HTML file in headless Chromium
// and prints one line per problem. Exit code 0: no problem; 1: problems found; 2: the check itself
// could not run (bad arguments, missing file, no browser).
//
// Usage: node check.js [--screenshots DIR] [--chromium PATH] REPORT_HTML
'use strict';

const fs = require('fs');
const os = require('os');
const path = require('path');
const { pathToFileURL } = require('url');

const MIN_FIGURE_TEXT_PX = 9;
const DESKTOP = { width: 1400, height: 900 };
const PHONE = { width: 390, height: 844 };
// Print layout width: A4 (210 mm) less the stylesheet's 2 x 14 mm page margins, at 96 px per inch.
const PRINT = { width: Math.round(((210 - 28) / 25.4) * 96), height: 1000 };

const LAUNCH_ARGS = [
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  // Nothing may resolve: the report must not reach the network, and this makes sure it cannot.
  '--host-resolver-rules=MAP * ~NOTFOUND',
];

function usage(msg) {
  if (msg) process.stderr.write(`browser-check: ${msg}\n`);
  process.stderr.write('usage: node check.js [--screenshots DIR] [--chromium PATH] REPORT_HTML\n');
  process.exit(2);
}

function parseArgs(argv) {
  const opts = { screenshots: null, chromium: process.env.CHROMIUM_PATH || null, report: null };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '--screenshots' || a === '--chromium') {
      if (i + 1 >= argv.length) usage(`${a} needs a value`);
      opts[a.slice(2)] = argv[++i];
    } else if (a.startsWith('--screenshots=')) {
      opts.screenshots = a.slice('--screenshots='.length);
    } else if (a.startsWith('--chromium=')) {
      opts.chromium = a.slice('--chromium='.length);
    } else if (a === '-h' || a === '--help') {
      usage();
    } else if (a.startsWith('-')) {
      usage(`unknown option ${a}`);
    } else if (opts.report === null) {
      opts.report = a;
    } else {
      usage(`unexpected argument ${a}`);
    }
  }
  if (opts.report === null) usage('no report file given');
  return opts;
}

function findChromium(explicit) {
  const candidates = explicit
    ? [explicit]
    : ['/usr/bin/chromium', '/usr/bin/chromium-browser', '/usr/bin/google-chrome'];
  for (const c of candidates) {
    try {
      fs.accessSync(c, fs.constants.X_OK);
      return c;
    } catch (_) {
      /* next */
    }
  }
  usage(
    `no Chromium found (tried ${candidates.join(', ')}); install it with ` +
      '`apt-get install -y chromium` or pass --chromium PATH'
  );
}

const { PAGE_HELPERS, pageMathProblems, pageFigureNameProblems, pageFontProblems, pagePrintProblems, pageSidewaysScroll, pageFigureTextProblems } = require('./page-checks');

// ---------------------------------------------------------------------------------------------

async function main() {
  const opts = parseArgs(process.argv.slice(2));
  const reportPath = path.resolve(opts.report);
  if (!fs.existsSync(reportPath) || !fs.statSync(reportPath).isFile()) {
    usage(`no such file: ${reportPath}`);
  }
  const executablePath = findChromium(opts.chromium);
  const reportUrl = pathToFileURL(reportPath).href;

  let chromium;
  try {
    ({ chromium } = require('playwright-core'));
  } catch (e) {
    usage('playwright-core is not installed: run `npm ci --no-audit --no-fund` in ' + __dirname);
  }

  // Each check category collects its problems; the summary counts categories.
  const results = new Map();
  const add = (check, lines) => {
    if (!results.has(check)) results.set(check, []);
    results.get(check).push(...lines);
  };
  // Console and network problems repeat in every context: one line each, naming the contexts.
  const seen = new Map();
  const addOnce = (check, label, line) => {
    const key = check + '\0' + line;
    if (seen.has(key)) {
      seen.get(key).push(label);
      return;
    }
    const labels = [label];
    seen.set(key, labels);
    add(check, [{ toString: () => `[${labels.join(', ')}] ${line}` }]);
  };
  const checks = [
    'console',
    'network',
    'fonts',
    'mathml',
    'figure-names',
    'print',
    'scroll-1400',
    'scroll-390',
    'figure-text-390',
  ];
  checks.forEach((c) => add(c, []));

  // Playwright's launch() gives the browser a fresh, empty temporary profile (user-data-dir) and
  // removes it on close.
  let browser;
  try {
    browser = await chromium.launch({
      executablePath,
      headless: true,
      chromiumSandbox: false, // passes --no-sandbox
      args: LAUNCH_ARGS,
      timeout: 60000,
    });
  } catch (e) {
    process.stderr.write(`browser-check: could not start ${executablePath}: ${e.message}\n`);
    process.exit(2);
  }

  const shotDir = opts.screenshots ? path.resolve(opts.screenshots) : null;
  if (shotDir) fs.mkdirSync(shotDir, { recursive: true });

  // Opens the report in a new context; records console errors, page errors and every request
  // other than the report itself (all of which are refused).
  async function open(contextOptions, label, media) {
    const context = await browser.newContext({
      ...contextOptions,
      javaScriptEnabled: true,
      serviceWorkers: 'block',
    });
    await context.route('**/*', (route) => {
      const url = route.request().url();
      if (url === reportUrl || url.split('#')[0] === reportUrl) return route.continue();
      addOnce('network', label, `request for ${url.slice(0, 120)} (blocked)`);
      return route.abort('blockedbyclient');
    });
    const page = await context.newPage();
    page.on('console', (msg) => {
      if (msg.type() !== 'error') return;
      const text = msg.text();
      // Blocked requests are already reported by the network check.
      if (/net::ERR_BLOCKED_BY_CLIENT/.test(text)) return;
      const loc = msg.location();
      const where = loc && loc.url ? ` at ${path.basename(loc.url)}:${loc.lineNumber + 1}` : '';
      addOnce('console', label, `console error${where}: ${text.slice(0, 200)}`);
    });
    page.on('pageerror', (err) => {
      addOnce('console', label, `uncaught page error: ${String(err.message || err).slice(0, 200)}`);
    });
    if (media) await page.emulateMedia({ media });
    await page.goto(reportUrl, { waitUntil: 'load', timeout: 60000 });
    await page.evaluate(() => document.fonts.ready);
    await page.evaluate(PAGE_HELPERS);
    await page.waitForTimeout(300); // late errors from timers
    return { context, page };
  }

  const openAllDetails = (page) =>
    page.evaluate(() => {
      document.querySelectorAll('details:not([open])').forEach((d) => (d.open = true));
      return document.body.offsetHeight; // force layout
    });

  try {
    // Desktop, 1400 px: console, network, fonts, MathML, figure names, sideways scroll.
    {
      const { context, page } = await open(
        { viewport: DESKTOP, deviceScaleFactor: 1 },
        '1400px'
      );
      add('fonts', await page.evaluate(pageFontProblems));
      add('figure-names', await page.evaluate(pageFigureNameProblems));
      add('scroll-1400', await page.evaluate(pageSidewaysScroll, '1400 px'));
      if (shotDir) {
        await page.screenshot({ path: path.join(shotDir, 'chromium-1400.png'), fullPage: true });
      }
      // What a reader can open must work too.
      await openAllDetails(page);
      add('mathml', await page.evaluate(pageMathProblems));
      if (results.get('scroll-1400').length === 0) {
        add('scroll-1400', await page.evaluate(pageSidewaysScroll, '1400 px with <details> opened'));
      }
      await context.close();
    }

    // Phone, 390 px: sideways scroll and the size of figure text.
    {
      const { context, page } = await open(
        { viewport: PHONE, deviceScaleFactor: 2, isMobile: true, hasTouch: true },
        '390px'
      );
      add('scroll-390', await page.evaluate(pageSidewaysScroll, '390 px'));
      if (shotDir) {
        await page.screenshot({ path: path.join(shotDir, 'chromium-390.png'), fullPage: true });
      }
      await openAllDetails(page);
      if (results.get('scroll-390').length === 0) {
        add('scroll-390', await page.evaluate(pageSidewaysScroll, '390 px with <details> opened'));
      }
      add(
        'figure-text-390',
        await page.evaluate(pageFigureTextProblems, { minPx: MIN_FIGURE_TEXT_PX, label: '390 px' })
      );
      await context.close();
    }

    // Print: with print media emulated at the A4 text width, every figure, caption, table and
    // equation must be displayed.
    {
      const { context, page } = await open(
        { viewport: PRINT, deviceScaleFactor: 1 },
        'print',
        'print'
      );
      add('print', await page.evaluate(pagePrintProblems));
      if (shotDir) {
        await page.pdf({
          path: path.join(shotDir, 'print.pdf'),
          format: 'A4',
          printBackground: true,
        });
      }
      await context.close();
    }
  } catch (e) {
    process.stderr.write(`browser-check: the check failed to run: ${e.stack || e}\n`);
    await browser.close().catch(() => {});
    process.exit(2);
  }
  await browser.close();

  let failed = 0;
  let problems = 0;
  for (const [check, lines] of results) {
    if (lines.length === 0) continue;
    failed++;
    for (const l of lines) {
      problems++;
      console.log(`FAIL ${check}: ${l}`);
    }
  }
  const passed = results.size - failed;
  for (const [check, lines] of results) if (lines.length === 0) console.log(`ok   ${check}`);
  if (shotDir) console.log(`screenshots and print PDF in ${shotDir}`);
  console.log(`${problems} problem(s) in ${reportPath}`);
  console.log(`browser-check: ${passed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
}

main().catch((e) => {
  process.stderr.write(`browser-check: ${e.stack || e}\n`);
  process.exit(2);
});
