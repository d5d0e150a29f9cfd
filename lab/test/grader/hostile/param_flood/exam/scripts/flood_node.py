#!/usr/bin/env python3
"""The parameter flood: FLOODS setParam calls of SIZE bytes each, which the master keeps in its own
memory (640 MB in all). Stops at the first failed call (the master gone); one string of SIZE bytes,
reused. Does nothing as root."""
import os

FLOODS = 10
SIZE = 64 << 20


def main():
    if os.geteuid() == 0:
        print('root: the flood does nothing', flush=True)
        return
    import rospy
    rospy.init_node('flood')
    blob = 'x' * SIZE
    for index in range(FLOODS):
        try:
            rospy.set_param('/flood/p%d' % index, blob)
        except Exception as err:  # the master is gone: nothing left to fill
            print('flood: call %d failed: %r' % (index, err), flush=True)
            break
        print('flood: %d MB set' % ((index + 1) * SIZE >> 20), flush=True)
    del blob
    rospy.spin()


if __name__ == '__main__':
    main()
