// Builds ONE self-contained dist/index.html: the bundled script and the CSS are written into the
// page, so it works opened from disk (Chromium refuses to load module scripts over file://).
import { defineConfig, type Plugin } from 'vite';

function inlineIntoHtml(): Plugin {
  return {
    name: 'mlmap-inline-into-html',
    apply: 'build',
    enforce: 'post',
    generateBundle(_options, bundle) {
      for (const html of Object.values(bundle)) {
        if (html.type !== 'asset' || !html.fileName.endsWith('.html')) continue;
        let page = String(html.source);
        for (const [name, item] of Object.entries(bundle)) {
          if (item.type === 'chunk' && name.endsWith('.js')) {
            const tag = new RegExp(`<script type="module" crossorigin src="[^"]*${escape(name)}"></script>`);
            if (!tag.test(page)) continue;
            // "</script" inside the code would end the element early.
            const code = item.code.replace(/<\/script/gi, '<\\/script');
            page = page.replace(tag, () => `<script type="module">${code}</script>`);
            delete bundle[name];
          } else if (item.type === 'asset' && name.endsWith('.css')) {
            const tag = new RegExp(`<link rel="stylesheet" crossorigin href="[^"]*${escape(name)}">`);
            if (!tag.test(page)) continue;
            page = page.replace(tag, () => `<style>${String(item.source)}</style>`);
            delete bundle[name];
          }
        }
        const left = Object.keys(bundle).filter((n) => n !== html.fileName);
        if (left.length) this.error(`files left outside index.html: ${left.join(', ')}`);
        html.source = page;
      }
    },
  };
}

const escape = (s: string) => s.replace(/[.*+?^${}()|[\]\\]/g, '\\$&');

export default defineConfig({
  base: './',
  plugins: [inlineIntoHtml()],
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    assetsInlineLimit: Number.MAX_SAFE_INTEGER,
    cssCodeSplit: false,
    modulePreload: { polyfill: false },
    chunkSizeWarningLimit: 2000,
  },
});
