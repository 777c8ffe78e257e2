"""The database store's schema and helpers: tables (one schema on SQLite and PostgreSQL, SQLAlchemy
Core), database URLs, JSON text columns, measurement ids ("m0000001" for row 1) and the dialect's
INSERT ... ON CONFLICT. JSON documents are text columns so that a result's shape can grow without a
migration; a change a version-1 reader would misread raises ``STORE_VERSION``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from ...core.errors import ParameterError


SQL_SUFFIXES = (".db", ".sqlite", ".sqlite3")
_RAW_KEY = re.compile(r"^[0-9a-f]{64}$")


def is_sql_target(target) -> bool:
    """Whether ``target`` names a database (a URL such as ``postgresql://user@host/db``, or a file whose
    suffix is .db, .sqlite or .sqlite3) rather than an HDF5 store file."""
    s = str(target)
    return "://" in s or Path(s).suffix.lower() in SQL_SUFFIXES


def _schema():
    """The tables, built once per process (SQLAlchemy is imported only when a database store is used)."""
    import sqlalchemy as sa
    md = sa.MetaData()
    sa.Table("vibmeasure", md, sa.Column("key", sa.String(64), primary_key=True), sa.Column("value", sa.Text))
    sa.Table("assets", md,
             sa.Column("asset", sa.String(200), primary_key=True), sa.Column("kind", sa.String(32)),
             sa.Column("bearing", sa.Text), sa.Column("gear", sa.Text), sa.Column("model", sa.Text),
             sa.Column("iso_group", sa.Integer), sa.Column("foundation", sa.String(16)), sa.Column("meta", sa.Text))
    sa.Table("points", md,
             sa.Column("asset", sa.String(200), sa.ForeignKey("assets.asset"), primary_key=True),
             sa.Column("point", sa.String(200), primary_key=True), sa.Column("channel", sa.Text),
             sa.Column("direction", sa.Text), sa.Column("unit", sa.Text))
    sa.Table("measurements", md,
             sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
             sa.Column("asset", sa.String(200), nullable=False), sa.Column("point", sa.String(200), nullable=False),
             sa.Column("time", sa.Float, nullable=False), sa.Column("rpm", sa.Float),
             sa.Column("sha256", sa.String(64), index=True), sa.Column("file", sa.Text),
             sa.Column("raw", sa.String(64)), sa.Column("meta", sa.Text),
             sa.ForeignKeyConstraint(["asset", "point"], ["points.asset", "points.point"]),
             sa.Index("ix_measurements_asset_point_time", "asset", "point", "time"))
    sa.Table("results", md,
             sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
             sa.Column("measurement", sa.Integer, sa.ForeignKey("measurements.id"), nullable=False),
             sa.Column("task", sa.String(200), nullable=False), sa.Column("version", sa.String(64)),
             sa.Column("created", sa.Float), sa.Column("params", sa.Text), sa.Column("summary", sa.Text),
             sa.Column("result", sa.Text),
             # the measurement's asset, point and time, copied at insert (a measurement never moves): a
             # trend reads one asset's results from one index without the join, whose rows lie one per
             # block in a plant's interleaved history (SQL_STORE_VERSION 2)
             sa.Column("asset", sa.String(200)), sa.Column("point", sa.String(200)), sa.Column("time", sa.Float),
             # no index on the task alone: a handful of tasks over millions of rows, and SQLite's planner
             # (no statistics) then scanned every result of the task instead of the asset's
             sa.Index("ix_results_measurement_task", "measurement", "task"))
    r = md.tables["results"]
    # one asset's results in key order. On PostgreSQL the index also carries what a results frame
    # without the documents reads, so that the query never visits the table (an index-only scan: 10 ms
    # for a year of one asset among 1M results, against 120 ms through the table); rows too wide for
    # a B-tree entry (2,704 bytes) are left to the second, partial index and read from the table
    wide = _wide(r)
    sa.Index("ix_results_asset_task_time", r.c.asset, r.c.task, r.c.time, postgresql_where=~wide,
             postgresql_include=["point", "measurement", "id", "version", "params", "summary"])
    sa.Index("ix_results_wide", r.c.asset, r.c.task, r.c.time, postgresql_where=wide).ddl_if(dialect="postgresql")
    # each change of a trend verdict (ok / watch / alarm) per asset, point and metric: the alarm history
    sa.Table("alarms", md,
             sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
             sa.Column("asset", sa.String(200), nullable=False), sa.Column("point", sa.String(200), nullable=False),
             sa.Column("task", sa.String(200), nullable=False), sa.Column("metric", sa.String(200), nullable=False),
             sa.Column("verdict", sa.String(16), nullable=False), sa.Column("value", sa.Float),
             sa.Column("limit_value", sa.Float), sa.Column("reason", sa.Text),
             sa.Column("time", sa.Float), sa.Column("created", sa.Float),
             sa.Index("ix_alarms_asset_point_metric", "asset", "point", "task", "metric", "id"))
    return md


# the database schema's version: 2 added the results' asset, point and time (``SQLStore`` upgrades a
# version-1 store it opens for writing, and reads one opened for reading through the join)
SQL_STORE_VERSION = 2
WIDE_BYTES = 2400   # a B-tree entry holds 2,704 bytes; the rest is the entry's header and fixed columns


def _wide(r):
    """Whether a result row is too wide for the covering index: its text columns' bytes over WIDE_BYTES.
    The same expression stands in the indexes' predicates and in the queries, its constants written
    out (a bound parameter would keep the planner from proving which index holds a row)."""
    import functools
    import operator

    import sqlalchemy as sa
    zero = sa.literal_column("0")
    size = functools.reduce(operator.add, [sa.func.coalesce(sa.func.octet_length(c), zero) for c in
                                           (r.c.asset, r.c.point, r.c.task, r.c.version, r.c.params, r.c.summary)])
    return size > sa.literal_column(str(WIDE_BYTES))


_MD = None


def _tables():
    global _MD
    if _MD is None:
        _MD = _schema()
    return _MD.tables


def _url(target) -> str:
    """The SQLAlchemy URL of a database target; a plain postgresql:// URL uses psycopg (version 3)."""
    s = str(target)
    if "://" not in s:
        return "sqlite:///" + str(Path(s).resolve())
    if s.startswith("postgresql://") or s.startswith("postgres://"):
        return "postgresql+psycopg://" + s.split("://", 1)[1]
    return s


def _dumps(obj) -> str:
    return json.dumps(obj, allow_nan=True)


def _loads(text):
    if text is None:
        return None
    try:
        return json.loads(text)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"the store is damaged: a stored value is not JSON ({exc})") from None


def _many(texts, empty) -> list:
    """Many JSON texts parsed at once (one array: the parser's call overhead once); a NULL or JSON null
    gives ``empty`` (a fresh copy of it for each row)."""
    try:
        values = json.loads("[" + ",".join("null" if t is None else t for t in texts) + "]")
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"the store is damaged: a stored value is not JSON ({exc})") from None
    if len(values) != len(texts):      # a text such as '1, 2' would split into two values
        raise ParameterError("the store is damaged: a stored value holds more than one JSON value")
    out = [(type(empty)() if empty is not None else None) if v is None else v for v in values]
    if isinstance(empty, dict) and any(not isinstance(v, dict) for v in out):
        raise ParameterError("the store is damaged: a stored mapping (params or summary) is not a mapping")
    return out


def _mid(n: int) -> str:
    return f"m{int(n):07d}"


def _mnum(measurement) -> int | None:
    """The row id of a measurement id such as "m0000012", or None for anything else."""
    if isinstance(measurement, str) and len(measurement) >= 8 and measurement[0] == "m" and measurement[1:].isdigit():
        return int(measurement[1:])
    return None


def _insert(conn, table):
    """An INSERT with ON CONFLICT support in the connection's dialect (SQLite or PostgreSQL)."""
    if conn.dialect.name == "postgresql":
        from sqlalchemy.dialects.postgresql import insert
    else:
        from sqlalchemy.dialects.sqlite import insert
    return insert(table)


def _short(exc) -> str:
    """The database's own message, first line, without SQLAlchemy's statement dump."""
    orig = getattr(exc, "orig", None)
    return str(orig if orig is not None else exc).strip().splitlines()[0][:300]
