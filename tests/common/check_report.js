// Opens an HTML report in headless Chromium (Debian package `chromium`, driven by npm
// `playwright-core`, found through NODE_PATH) with every network request refused and
// JavaScript off, as a reader on a file share would open it, and prints what it saw as JSON:
// console errors, page errors, requests that left the file, each <img>'s load state, each
// inline <svg>'s box; saves an A4-sized screenshot (794 x 1123 CSS pixels: 210 x 297 mm at
// 96 px per inch) of its first page.
// Usage: node check_report.js REPORT.html SCREENSHOT.png
// Exit status 0 with the JSON when the page was opened, 2 when the browser is unavailable
// (playwright-core or Chromium missing), 1 on any other failure.
const path = require('path');
const { pathToFileURL } = require('url');

// The A4 page at CSS's 96 pixels per inch.
const A4 = { width: 794, height: 1123 };
// Where Debian's package puts Chromium; CHROMIUM overrides it.
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';

function unavailable(why) {
  process.stderr.write(`${why}\n`);
  process.exit(2);
}

async function main() {
  const [file, screenshot] = process.argv.slice(2);
  let chromium;
  try {
    ({ chromium } = require('playwright-core'));
  } catch (e) {
    unavailable(`npm playwright-core: ${e.message.split('\n')[0]}`);
  }
  let browser;
  try {
    // Root in a container has no user namespaces for Chromium's sandbox.
    browser = await chromium.launch({ executablePath: CHROMIUM, args: ['--no-sandbox'] });
  } catch (e) {
    unavailable(`${CHROMIUM}: ${e.message.split('\n')[0]}`);
  }
  const context = await browser.newContext({ viewport: A4, javaScriptEnabled: false });
  const page = await context.newPage();
  const seen = { consoleErrors: [], pageErrors: [], requests: [] };
  page.on('console', (m) => { if (m.type() === 'error') seen.consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => seen.pageErrors.push(String(e)));
  // Only the file itself may be read: anything else is recorded and refused.
  const url = pathToFileURL(path.resolve(file)).href;
  await context.route('**/*', (route) => {
    const wanted = route.request().url();
    if (wanted === url) return route.continue();
    seen.requests.push(wanted);
    return route.abort();
  });
  await page.goto(url, { waitUntil: 'load' });
  seen.images = await page.$$eval('img', (imgs) =>
    imgs.map((i) => ({ alt: i.alt, complete: i.complete, naturalWidth: i.naturalWidth })));
  seen.svgs = await page.$$eval('svg', (svgs) => svgs.map((s) => {
    const box = s.getBoundingClientRect();
    return { width: box.width, height: box.height };
  }));
  await page.screenshot({ path: screenshot });
  await browser.close();
  process.stdout.write(JSON.stringify(seen));
}

main().catch((e) => {
  process.stderr.write(`${e.stack || e}\n`);
  process.exit(1);
});
