# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's ``main``: start it, spin it until a stop, and say in one line why it could not.

:func:`main` runs :class:`~mech_kinematics.ros.node.KinematicsNode` as the
``kinematics_node`` executable (:mod:`mech_kinematics.kinematics_node` calls
it). It works on Jazzy and Kilted: ``rclpy.init()``, ``try: spin`` / ``except
(KeyboardInterrupt, ExternalShutdownException)`` / ``finally: destroy_node();
rclpy.try_shutdown()``. Until the node spins, a SIGINT or SIGTERM is only
noted and the start stops at its next step
(:mod:`~mech_kinematics.ros.startup`); rclpy's own handler is installed just
before the spin. A start that fails is one line, ``cannot start: REASON``,
and an exit status: 0 when stopped (a signal at any point of the start
included), 1 if the node cannot start (a bad argument or parameter, a scene
that cannot be loaded or assembled, an older node of the same name: see
:mod:`~mech_kinematics.ros.instance`) or its tick thread failed, 2 if a file
its arguments name may not be read.
"""

from __future__ import annotations

import gc
import os
import sys
import time
import warnings

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.logging import get_logger
from rclpy.signals import install_signal_handlers, SignalHandlerOptions

from .instance import DuplicateNodeError, Instance
from .node import KinematicsNode, NODE_NAME, one_line, StartError
from .startup import catch_stop_signals, start_refusal, stop_asked, StopRequested
from .tick_thread import TickThreadError
from ..errors import NearSingularWarning

__all__ = ['SWITCH_INTERVAL_S', 'main']

#: Longest time another thread may hold the GIL before the tick thread gets it, s.
SWITCH_INTERVAL_S = 0.0005


class _Executor(SingleThreadedExecutor):
    """rclpy's executor; one half built (a signal shut its context down) deletes quietly."""

    # Executor.__del__ reads it: without this, an executor whose __init__ failed prints
    # "Exception ignored ... AttributeError" when it is collected.
    _sigint_gc = None


def main(args: list[str] | None = None) -> int:
    """Run the node until Ctrl-C or SIGTERM; return the exit status.

    0 when stopped (a SIGINT or SIGTERM at any point of the start included), 1 if
    it cannot start, 2 if a file its arguments name may not be read
    (:mod:`~mech_kinematics.ros.startup`).
    """
    catch_stop_signals()
    # The node reports near-singular poses on diagnostics and in its log.
    warnings.filterwarnings('ignore', category=NearSingularWarning)
    # The tick thread must not wait long for the GIL when it wakes (default 5 ms).
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    logger = get_logger(NODE_NAME)
    start_ns = time.time_ns()
    refused = start_refusal(sys.argv if args is None else args)
    if refused is not None:
        logger.fatal(f'cannot start: {refused}')
        return 2
    if stop_asked():
        return 0
    try:
        # Until the spin a signal is only noted (startup.catch_stop_signals), and the start
        # stops at its next step: rclpy's handler would shut the context down under the
        # step running (a SIGINT while configuring crashed the process with SIGSEGV).
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:     # noqa: BLE001 - rclpy's argument errors come in several kinds
        logger.fatal(f'cannot start: bad arguments: {one_line(exc)}')
        return 1
    node = None
    status = 0
    stopped_in_read: StopRequested | None = None
    try:
        if stop_asked():
            return 0
        node = KinematicsNode()
        logger = node.get_logger()
        Instance(node, start_ns)
        assert node.params is not None
        if not node.managed and not stop_asked():
            node.trigger_configure()
            if node.scene is None and not stop_asked():
                logger.fatal(f'cannot start: {node.configure_error}')
                return 1
        node.params.starting = False
        if not node.managed and not stop_asked():
            node.trigger_activate()
        # Everything built so far lives as long as the node: keep it out of the
        # garbage collector's full passes, which would otherwise delay ticks.
        gc.freeze()
        # The executor is made before rclpy's handler is installed: a signal that shut the
        # context down while it was made left its guard condition half built, whose
        # deletion printed "Exception ignored ... AttributeError" (one run in 7 stops).
        executor = _Executor()
        executor.add_node(node)
        # From now on rclpy's handler ends the spin on a signal (and calls ours); a signal
        # noted before it was installed is seen here.
        install_signal_handlers(SignalHandlerOptions.ALL)
        if stop_asked():
            return 0
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl-C or shutdown: a clean exit, status 0
    except StopRequested as stop:
        # A stop while the start read the scene or robot: a clean exit, status 0, without
        # freeing what the read built (the exception's frames hold it: kept below). Freeing
        # a 40,000-joint URDF's trees took 1.1-1.5 s at load 11; os._exit skips it.
        stopped_in_read = stop
    except TickThreadError:
        status = 1
    except DuplicateNodeError as exc:
        logger.fatal(f'cannot start: {exc}')
        status = 1
    except StartError as exc:
        if not stop_asked():
            get_logger(exc.logger_name).fatal(f'cannot start: {exc.reason}')
            status = 1
    except Exception as exc:     # noqa: BLE001 - a start-up failure: one line, no traceback
        if rclpy.ok() and not stop_asked():
            logger.fatal(f'cannot start: {one_line(exc)}')
            status = 1
        # else a signal shut the context down while the node started (rclpy's own
        # handler): what failed then is the shutdown asked for, a clean exit, status 0
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    if stopped_in_read is not None:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return status


if __name__ == '__main__':
    sys.exit(main())
