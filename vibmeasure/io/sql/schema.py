"""The database store's schema and helpers: tables, URLs, JSON columns, measurement ids, dialect inserts.

The measurement store on a relational database: SQLite for one machine, PostgreSQL for a plant.

One schema (SQLAlchemy Core, ``SCHEMA``) on both engines: assets, points, measurements and results,
each result with the vibmeasure version and the parameters that produced it; JSON documents (meta,
params, summary, result) are text columns, so a result's shape can grow without a migration. Raw
records are not in the database: each is a sealed vibmeasure HDF5 file named by its content's
SHA-256 in a folder beside the database (``raw_dir``), written before its row is committed.

Durability and concurrency are the engine's: rows added since the last ``commit()`` form one
transaction, so a process killed at any moment loses only those. SQLite runs in WAL mode (readers
never block the writer, nor it them) with ``synchronous=FULL`` and waits up to ``timeout`` seconds
for another writer's transaction; PostgreSQL takes many writers at once (a batch's Dask workers, a
plant's collectors), each measurement id from one sequence.
"""

from __future__ import annotations

import json
import re
from pathlib import Path


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
             sa.Column("measurement", sa.Integer, sa.ForeignKey("measurements.id"), nullable=False, index=True),
             sa.Column("task", sa.String(200), nullable=False, index=True), sa.Column("version", sa.String(64)),
             sa.Column("created", sa.Float), sa.Column("params", sa.Text), sa.Column("summary", sa.Text),
             sa.Column("result", sa.Text))
    return md


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
    return None if text is None else json.loads(text)


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
