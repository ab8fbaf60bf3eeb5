// Helpers shared by the end-to-end test and screenshot.mjs: headless Debian chromium through
// playwright-core, and a tiny static file server on 127.0.0.1.
import { createServer } from 'node:http';
import { mkdtemp, readFile, rm, stat } from 'node:fs/promises';
import { existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';

export const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';

export async function launchChromium() {
  if (!existsSync(CHROMIUM)) throw new Error(`${CHROMIUM} is missing: apt-get install chromium (scripts/web-test.sh does)`);
  const userDataDir = await mkdtemp(path.join(tmpdir(), 'mlmap-web-chromium-'));
  const args = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    '--enable-unsafe-swiftshader', '--use-angle=swiftshader'];
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: CHROMIUM, headless: true, args, viewport: { width: 1440, height: 900 },
  });
  // Software WebGL on a shared, loaded machine: loading a page can take well over the 30 s default.
  context.setDefaultTimeout(120_000);
  return { context, userDataDir };
}

/** Closes what launchChromium started and removes its profile directory; nothing when it never started. */
export async function closeChromium(browser) {
  if (!browser) return;
  await browser.context.close();
  await rm(browser.userDataDir, { recursive: true, force: true });
}

/** Waits (within the context's timeout) until the 3D view shows the page's state with every box drawn. */
export function waitDrawn(page) {
  return page.waitForFunction(() => window.mlmapDashboard?.drawing()?.complete ?? true);
}

const TYPES = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8', '.json': 'application/json', '.png': 'image/png' };

/** Serves the files under root on 127.0.0.1 at a random port; returns { url, close }. */
export async function serveDir(root) {
  const server = createServer(async (req, res) => {
    try {
      const url = new URL(req.url ?? '/', 'http://x');
      let file = path.join(root, decodeURIComponent(url.pathname));
      if (!file.startsWith(path.resolve(root))) throw new Error('outside');
      if ((await stat(file)).isDirectory()) file = path.join(file, 'index.html');
      const body = await readFile(file);
      res.writeHead(200, { 'content-type': TYPES[path.extname(file)] ?? 'application/octet-stream' });
      res.end(body);
    } catch {
      res.writeHead(404, { 'content-type': 'text/plain' });
      res.end('not found');
    }
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  const { port } = server.address();
  return {
    url: `http://127.0.0.1:${port}`,
    close: () => new Promise((resolve) => { server.closeAllConnections(); server.close(resolve); }),
  };
}

/** The planes.js that `mlmap export --dashboard` writes beside the page. */
export function planesJs(jsonText) {
  return `window.MLMAP_PLANES = ${jsonText.trim()};\n`;
}
