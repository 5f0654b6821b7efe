# SPDX-License-Identifier: MIT
# Sphinx configuration of the documentation site (built by scripts/docs.sh into build/docs/).
#
# Why Sphinx + furo + breathe + myst-parser (all Debian 12 packages): the Python API comes from the module's
# docstrings with autodoc and the C++ API from the headers with breathe (through doxygen's XML), neither of which
# Debian's mkdocs 1.4 / mkdocs-material 8 can do without mkdocstrings (not in Debian); myst-parser keeps the pages
# in Markdown, readable as they are on a repository browser.
import os

from sphinx import addnodes
from sphinx.transforms.post_transforms import SphinxPostTransform

project = "trivcon"
author = "the trivcon authors"
copyright = "the trivcon authors"

extensions = ["myst_parser", "breathe", "sphinx.ext.autodoc"]
source_suffix = {".md": "markdown"}
master_doc = "index"
exclude_patterns = ["Doxyfile", "_build"]
myst_heading_anchors = 3
suppress_warnings = []

# The C++ API: doxygen's XML, written by scripts/docs.sh (docs/Doxyfile) into build/doxygen/xml.
breathe_projects = {"trivcon": os.environ.get("TRIVCON_DOXYGEN_XML", os.path.join(os.path.dirname(__file__), "..", "build", "doxygen", "xml"))}
breathe_default_project = "trivcon"
breathe_default_members = ("members",)
breathe_show_include = True

# The Python API: the installed module (scripts/docs.sh runs Sphinx with build/venv's Python, where it is installed).
autodoc_member_order = "bysource"
autodoc_typehints = "none"

html_theme = "furo"
html_title = "trivcon"
html_static_path = []
html_show_sourcelink = False

# Links from these pages to the repository's own Markdown files outside docs/ (which read right on a repository
# browser) go to the site's pages that include those files.
REPOSITORY_PAGES = {"BENCHMARKS.md": "benchmarks/full", "ARCHITECTURE.md": "development/architecture"}


class RepositoryPageLinks(SphinxPostTransform):
    """Before MyST resolves [text](../BENCHMARKS.md), point it at the page that includes that file."""

    default_priority = 8  # MyST's resolver is 9

    def run(self, **kwargs):
        env = self.env
        for node in self.document.findall(addnodes.pending_xref):
            if node.get("reftype") != "myst":
                continue
            target, _, anchor = node["reftarget"].partition("#")
            here = os.path.dirname(env.doc2path(node["refdoc"]))
            path = os.path.relpath(os.path.normpath(os.path.join(here, target)), os.path.join(env.srcdir, ".."))
            doc = REPOSITORY_PAGES.get(path)
            if doc is not None:
                node["reftarget"] = os.path.relpath(os.path.join(env.srcdir, doc), here) + ".md" + ("#" + anchor if anchor else "")


def docstring_as_text(app, what, name, obj, options, lines):
    """The module's docstrings are plain text, written for help(): show them as written, not as reStructuredText."""
    text = [line for line in lines]
    while text and not text[-1].strip():
        text.pop()
    if not text:
        return
    lines[:] = ["::", ""] + ["   " + line for line in text] + [""]


def setup(app):
    app.add_post_transform(RepositoryPageLinks)
    app.connect("autodoc-process-docstring", docstring_as_text)
    patch_breathe_namespace()


def patch_breathe_namespace():
    """Render a header's namespace trivcon as its members only: breathe's doxygenfile declares the namespace once
    per header, and Sphinx takes every repetition for a duplicate declaration (every header is in trivcon)."""
    from breathe.renderer import sphinxrenderer

    def visit_namespace(self, node):
        file_data = self.compound_parser.parse(node.refid)
        parent_context = self.context.create_child_context(file_data)
        new_context = parent_context.create_child_context(file_data.compounddef)
        with sphinxrenderer.WithContext(self, new_context):
            return self.render(file_data, parent_context)

    sphinxrenderer.SphinxRenderer.visit_namespace = visit_namespace
