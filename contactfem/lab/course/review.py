"""What the grader writes besides the CSV: the review files of the written answers and a feedback
file per student.

``REVIEW/LECTURE.html``: one section per student, code and answer side by side, each answer cut
at :data:`ANSWER_CHARS` characters (a notebook of any size makes a page of bounded size);
``REVIEW/LECTURE-scores.csv``: the sheet for the instructor's scores, written once (it is
theirs), read back into the CSV on the next run. ``FEEDBACK/ID-LECTURE.md``: the student's
score per part and the hints. Every file is written through a temporary file renamed into
place (:func:`contactfem.io.outputs.write_atomic`), in folders that are not symbolic links.
"""

import csv
import datetime as dt
import html
import io
import re
from pathlib import Path

from ...io.outputs import write_atomic
from .checks import BUILDS_ON, EXERCISES, MANUAL

ANSWER_CHARS = 20_000  # of one written answer or its code in the review file: pages, not a book


def bounded(text, limit=ANSWER_CHARS):
    return text if len(text) <= limit else text[:limit] + f"\n[... {len(text) - limit} more characters not shown]"


def csv_text(fields, rows):
    out = io.StringIO()
    w = csv.DictWriter(out, fieldnames=fields)
    w.writeheader()
    w.writerows(rows)
    return out.getvalue()


def read_manual_scores(path):
    """{(submission, question): score} of the instructor's scores file (blank: not scored)."""
    if not path.is_file():
        return {}
    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            text = (r.get("score") or "").strip()
            if not text:
                continue
            q = r.get("question", "")
            try:
                v = float(text)
            except ValueError:
                raise ValueError(f"{path}: score {text!r} of {r.get('submission')}, {q} is not a number") from None
            top = MANUAL[q].points if q in MANUAL else None
            if top is not None and not 0 <= v <= top:
                raise ValueError(f"{path}: score {v:g} of {r.get('submission')}, {q} is outside 0..{top:g}")
            out[(r.get("submission", ""), q)] = v
    return out


def write_reviews(review, lectures, details, scores_read):
    """REVIEW/LECTURE.html (one section per student, code and answer side by side) and
    REVIEW/LECTURE-scores.csv for the instructor's scores (kept if it exists: it is theirs)."""
    for lec in lectures:
        qs = [m for m in MANUAL.values() if m.lecture == lec]
        if not qs:
            continue
        mine = [d for d in details if d["lecture"] == lec and d["row"]["submission"]]
        parts = [
            f"<!doctype html><meta charset=utf-8><title>Written answers: {html.escape(lec)}</title>",
            "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;width:100%}"
            "td,th{border:1px solid #ccc;vertical-align:top;padding:.5em;width:50%}"
            "pre{white-space:pre-wrap;margin:0}section{margin-bottom:2em}</style>",
            f"<h1>Written answers: {html.escape(lec)}</h1>",
            f"<p>{len(mine)} submissions. Enter the scores in <code>{html.escape(lec)}-scores.csv</code> "
            "(column score) and run <code>contactfem course grade</code> again: they go into the CSV.</p>",
        ]
        for d in mine:
            r = d["row"]
            who = " ".join(x for x in (r["id"], r["name"]) if x) or r["submission"]
            parts.append(
                f'<section id="{html.escape(r["submission"])}"><h2>{html.escape(who)}</h2>'
                f"<p>{html.escape(r['submission'])}</p>"
            )
            for q in qs:
                code, text = d["answers"].get(q.name, ("", ""))
                given = scores_read.get(lec, {}).get((r["submission"], q.name))
                score = f"{given:g}" if given is not None else "not scored"
                parts.append(
                    f"<h3>{html.escape(q.name)} ({q.points:g} points; {score}): {html.escape(q.what)}</h3>"
                    "<table><tr><th>code</th><th>answer</th></tr><tr>"
                    f"<td><pre>{html.escape(bounded(code)) or '(no code)'}</pre></td>"
                    f"<td><pre>{html.escape(bounded(text)) or '(no answer)'}</pre></td></tr></table>"
                )
            parts.append("</section>")
        write_atomic(review / f"{lec}.html", "\n".join(parts))
        sheet = review / f"{lec}-scores.csv"
        if not sheet.exists():
            rows = [
                {
                    "submission": d["row"]["submission"],
                    "id": d["row"]["id"],
                    "name": d["row"]["name"],
                    "question": q.name,
                    "points": f"{q.points:g}",
                    "score": "",
                }
                for d in mine
                for q in qs
            ]
            write_atomic(sheet, csv_text(["submission", "id", "name", "question", "points", "score"], rows))


def write_feedback(feedback, details):
    """FEEDBACK/<id or submission>-<lecture>.md: the student's score per part and the hints."""
    for d in details:
        r = d["row"]
        stem = r["id"] or Path(r["submission"]).with_suffix("").as_posix()
        stem = re.sub(r"[^\w.-]", "_", stem).lstrip(".") or "submission"  # one file name, in this folder
        lines = [
            f"# {d['lecture'] or 'course'}: feedback for {r['name'] or r['id'] or r['submission']}",
            "",
            f"Total: {r['total']} of {r['possible']} ({r['status']}).",
        ]
        if d.get("received"):  # what was graded: the copy taken before any notebook ran
            when = dt.datetime.fromtimestamp(d["received"].mtime).astimezone().isoformat(timespec="seconds")
            lines.append(f"Graded: the file received {when}, SHA-256 {d['received'].sha256}.")
        if r["late"]:
            lines.append("Submitted late.")
        if r["status"] != "graded" or r["notes"] and not d["parts"]:
            lines += ["", f"Notes: {r['notes']}"]
        for e in [e for e in EXERCISES.values() if e.lecture == d["lecture"]]:
            ps = [p for p in d["parts"] if p[0] == e.name]
            got = sum(p[2] for p in ps)
            lines += ["", f"## {e.name}: {got:g} of {e.points:g}", f"{e.what}", ""]
            if e.name in BUILDS_ON:
                lines[-1:] = [f"(It builds on the library on purpose: {BUILDS_ON[e.name]}.)", ""]
            for _, part, pts, possible, msg in ps:
                lines.append(f"- {part}: {pts:g} of {possible:g}" + ("" if msg == "passed" else f": {msg}"))
        for q in d["manual"]:
            m = MANUAL[q]
            got = f"{r[q]} of {m.points:g}" if r.get(q) else f"to be scored, {m.points:g} points"
            lines += ["", f"## {q} (written): {got}", m.what]
        write_atomic(feedback / f"{stem}-{d['lecture'] or 'none'}.md", "\n".join(lines) + "\n")
